"""kage.ppo.fast.triton_conv's kernels compiled for the H100 (sm_90) as the trainer runs them, in bfloat16, on a
machine without a GPU: Triton's own compiler and the ptxas it ships, every autotuning config of every kernel, at
each NatureCNN layer's shapes (conv1 on the uint8 4 x 4 blocks of the frames, conv2 at stride 2), and the gather
of frames into those blocks, the fused ReLU in and out. The interpreter
(test_triton_interpreter.py) checks the values in float32 but never types bf16 code; this catches what only the
compiler sees (dtype mismatches in tl.dot and tl.where, unsupported tile shapes) before a GPU lease is spent on it.
The values in bf16 are checked on the GPU (tests/gpu/test_triton_conv.py)."""
import pytest
import triton
from triton.backends.compiler import GPUTarget
from triton.compiler import ASTSource

from kage.ppo.fast import triton_conv as tc

H100 = GPUTarget("cuda", 90, 32)
# (name, H, W, Cin, Cout, kh, kw, stride) of the convolutions the kernels run: conv1 as 2 x 2 over the uint8
# 32 x 32 x 48 blocks of the 128 x 128 x 3 frames, conv2 striding over conv1's 31 x 31 x 32 output, conv3.
LAYERS = [("conv1", 32, 32, 48, 32, 2, 2, 1), ("conv2", 31, 31, 32, 64, 4, 4, 2),
          ("conv3", 14, 14, 64, 64, 3, 3, 1)]
# Each kernel's pointer and run-time integer arguments, as _forward, _dgrad and _wgrad pass them under --bf16 on
# activations; conv1's x is the uint8 blocks.
SIGNATURES = {
    tc.forward_kernel: {"x_ptr": "*bf16", "w_ptr": "*bf16", "bias_ptr": "*fp32", "y_ptr": "*bf16", "B": "i32"},
    tc.dgrad_kernel: {"dy_ptr": "*bf16", "y_ptr": "*bf16", "w_ptr": "*bf16", "dx_ptr": "*bf16", "B": "i32"},
    tc.wgrad_kernel: {"x_ptr": "*bf16", "dy_ptr": "*bf16", "y_ptr": "*bf16", "parts_ptr": "*fp32",
                      "bias_parts_ptr": "*fp32", "B": "i32", "CHUNK": "i32", "SPLIT": "i32"},
}
NAMES = {tc.forward_kernel: "forward_kernel", tc.dgrad_kernel: "dgrad_kernel", tc.wgrad_kernel: "wgrad_kernel"}


def compile_for_h100(fn, types: dict, constants: dict, num_warps: int = 4, num_stages: int = 3):
    """The jitted function `fn`'s cubin for sm_90 with the given argument types and compile-time constants."""
    source = ASTSource(fn=fn, signature={name: types.get(name, "constexpr") for name in fn.arg_names},
                       constexprs={(fn.arg_names.index(name),): value for name, value in constants.items()})
    return triton.compile(source, target=H100, options={"num_warps": num_warps, "num_stages": num_stages})


# conv1's input gradient is never computed (the frames need none): the trainer never runs dgrad on conv1.
CASES = [(kernel, layer, index) for kernel in SIGNATURES for layer in LAYERS
         for index in range(len(kernel.configs)) if not (kernel is tc.dgrad_kernel and layer[0] == "conv1")]


@pytest.mark.parametrize("kernel, layer, index", CASES,
                         ids=[f"{NAMES[k]}-{layer[0]}-config{i}" for k, layer, i in CASES])
def test_kernel_compiles_for_the_h100_in_bf16(kernel, layer, index):
    name, h, w, cin, cout, kh, kw, stride = layer
    constants = dict(H=h, W=w, OH=(h - kh) // stride + 1, OW=(w - kw) // stride + 1, CIN=cin, COUT=cout, KH=kh,
                     KW=kw)
    constants["STRIDE"] = stride
    if kernel is not tc.dgrad_kernel:  # their tiles span the whole output width (triton_conv._width_block)
        constants["BLOCK_N"] = tc._width_block(cout)
    types = dict(SIGNATURES[kernel])
    if name == "conv1":
        types["x_ptr"] = "*u8"
    config = kernel.configs[index]
    # The fused ReLU under every config (the trainer's path); without it under the first.
    for relu in (True, False) if index == 0 else (True,):
        compiled = compile_for_h100(kernel.fn, types, dict(constants, RELU=relu, **config.kwargs),
                                    config.num_warps, config.num_stages)
        assert len(compiled.asm["cubin"]) > 0 and NAMES[kernel] in compiled.asm["ptx"], (NAMES[kernel], relu)


def test_blocks_kernel_compiles_for_the_h100():
    """The gather of 128 x 128 x 3 frames into 4 x 4 blocks, as frames_to_blocks launches it."""
    types = {"frames_ptr": "*u8", "images_ptr": "*i64", "blocks_ptr": "*u8"}
    compiled = compile_for_h100(tc.blocks_kernel, types, dict(H=128, W=128, C=3, S=4, BLOCK=2048))
    assert len(compiled.asm["cubin"]) > 0 and "blocks_kernel" in compiled.asm["ptx"]
