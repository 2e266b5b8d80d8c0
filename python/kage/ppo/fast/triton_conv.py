"""The baseline's convolutions for K packed runs as Triton implicit-GEMM kernels (--triton-conv): the run is a
grid axis instead of a channel group, so each layer and pass is one launch over all K runs, and the patches
are never materialised (cuDNN runs grouped convolutions group by group with slicing copies; im2col + bmm
moved more bytes than it saved: lab/2026-11-23-h100-packed-training-speed). Activations are [K, B, H, W, C]
(NHWC per run). conv1 runs as the equal 2 x 2 convolution over 4 x 4 blocks of the frames (space-to-depth):
one kernel gathers a minibatch's uint8 frames from the rollout buffer straight into blocks (the gather and the
rearrangement in one pass, still uint8), and the kernels read those bytes as the integers they are, the 1 / 255
folded into conv1's weight. conv2 and conv3 stride over their input as it lies, so no activation is copied into
another layout. The parameters keep nn.Conv2d(groups=K)'s layout, so checkpoints are the same. Imported only
under --triton-conv: triton is a GPU-machine dependency (and the CI tests'). Checked and timed on the GPU by
tests/gpu/test_triton_conv.py, and in float32 on the CPU under Triton's interpreter by
tests/python/test_triton_interpreter.py.
"""
from typing import Tuple

import torch
import triton
import triton.language as tl

from kage.ppo.fast.space_to_depth import weight_space_to_depth

# The reduction spans are conv1's 2 x 48 block bytes a filter row, conv2's 4 x 32 (stride 2) and conv3's 3 x 64;
# outputs are 32/64/64 channels. A program's output tile covers the whole output width (BLOCK_N) in the forward
# pass and the weight gradient, so the configs tune the rest; the input gradient's width is conv2's 2 x 2 x 32
# and conv3's 64 (a block of input positions). (A 256-tap weight-gradient tile, all of conv1's 192 taps at once,
# was never chosen on an H100: lab/2026-11-26-h100-conv-kernels.)
_FORWARD_CONFIGS = [triton.Config({"BLOCK_M": m, "BLOCK_K": k}, num_warps=w, num_stages=s)
                    for m, k, w, s in ((128, 32, 4, 3), (128, 64, 4, 3), (64, 32, 4, 4), (128, 64, 8, 4))]
_DGRAD_CONFIGS = [triton.Config({"BLOCK_M": m, "BLOCK_N": n, "BLOCK_K": k}, num_warps=w, num_stages=s)
                  for m, n, k, w, s in ((128, 64, 32, 4, 3), (128, 128, 32, 8, 3), (64, 64, 64, 4, 4),
                                        (128, 64, 64, 8, 3), (64, 128, 64, 4, 3))]
_WGRAD_CONFIGS = [triton.Config({"BLOCK_D": d, "BLOCK_M": m}, num_warps=w, num_stages=s)
                  for d, m, w, s in ((64, 64, 4, 3), (128, 64, 4, 3), (64, 128, 4, 4), (128, 128, 8, 3))]
_SHAPE_KEY = ["B", "H", "W", "CIN", "COUT", "KH", "KW", "STRIDE", "RELU"]


@triton.jit
def blocks_kernel(frames_ptr, images_ptr, blocks_ptr, H: tl.constexpr, W: tl.constexpr, C: tl.constexpr,
                  S: tl.constexpr, BLOCK: tl.constexpr):
    """blocks[i, bh, bw, (c, p, q)] = frames[images[i], S * bh + p, S * bw + q, c] (uint8, NHWC frames): one
    program moves one strip of S image rows, which is one contiguous row of blocks, so its stores are
    contiguous and its loads stay within the strip's S * W * C bytes."""
    STRIP: tl.constexpr = W // S * S * S * C
    i = tl.program_id(0).to(tl.int64)
    bh = tl.program_id(1)
    at = tl.arange(0, BLOCK)
    ok = at < STRIP
    bw = at // (S * S * C)
    channel = at % (S * S * C)
    c = channel // (S * S)
    p = channel // S % S
    q = channel % S
    image = tl.load(images_ptr + i).to(tl.int64)
    pixels = tl.load(frames_ptr + (((image * H + bh * S + p) * W + bw * S + q) * C + c), mask=ok)
    tl.store(blocks_ptr + ((i * (H // S) + bh) * STRIP + at), pixels, mask=ok)


@triton.autotune(configs=_FORWARD_CONFIGS, key=_SHAPE_KEY)
@triton.jit
def forward_kernel(x_ptr, w_ptr, bias_ptr, y_ptr, B,
                   H: tl.constexpr, W: tl.constexpr, OH: tl.constexpr, OW: tl.constexpr,
                   CIN: tl.constexpr, COUT: tl.constexpr, KH: tl.constexpr, KW: tl.constexpr,
                   STRIDE: tl.constexpr, RELU: tl.constexpr,
                   BLOCK_M: tl.constexpr, BLOCK_N: tl.constexpr, BLOCK_K: tl.constexpr):
    """y[run, m, co] = bias + sum over (kh, kw, ci) of x[image, S * oh + kh, S * ow + kw, ci] * w[run, kh, kw,
    ci, co], m = (b, oh, ow), image = run * B + b, then max(y, 0) under RELU. x is read in w's dtype (uint8
    blocks of frames as the integers they are). For one kh the (kw, ci) pairs are KW * CIN contiguous input
    elements (NHWC), so the reduction walks kh and BLOCK_K-wide pieces of that span: contiguous, coalesced
    loads."""
    STEPS: tl.constexpr = (KW * CIN + BLOCK_K - 1) // BLOCK_K
    run = tl.program_id(2).to(tl.int64)
    rows = tl.program_id(0) * BLOCK_M + tl.arange(0, BLOCK_M)
    cols = tl.program_id(1) * BLOCK_N + tl.arange(0, BLOCK_N)
    row_ok = rows < B * (OH * OW)
    col_ok = cols < COUT
    b = rows // (OH * OW)
    oh = rows // OW % OH
    ow = rows % OW
    x_row = (((run * B + b) * H + oh * STRIDE) * W + ow * STRIDE) * CIN
    w_run = w_ptr + run * (KH * KW * CIN * COUT)
    acc = tl.zeros((BLOCK_M, BLOCK_N), dtype=tl.float32)
    for step in range(0, KH * STEPS):
        kh = step // STEPS
        span = step % STEPS * BLOCK_K + tl.arange(0, BLOCK_K)
        span_ok = span < KW * CIN
        patch = tl.load(x_ptr + (x_row[:, None] + (kh * (W * CIN) + span)[None, :]),
                        mask=row_ok[:, None] & span_ok[None, :], other=0).to(w_ptr.dtype.element_ty)
        weight = tl.load(w_run + ((kh * (KW * CIN) + span)[:, None] * COUT + cols[None, :]),
                         mask=span_ok[:, None] & col_ok[None, :], other=0.0)
        acc += tl.dot(patch, weight)
    acc += tl.load(bias_ptr + run * COUT + cols, mask=col_ok, other=0.0)[None, :]
    if RELU:
        acc = tl.maximum(acc, 0.0)
    y_run = y_ptr + (run * B) * (OH * OW * COUT)
    tl.store(y_run + (rows.to(tl.int64)[:, None] * COUT + cols[None, :]), acc.to(y_ptr.dtype.element_ty),
             mask=row_ok[:, None] & col_ok[None, :])


@triton.autotune(configs=_DGRAD_CONFIGS, key=_SHAPE_KEY)
@triton.jit
def dgrad_kernel(dy_ptr, y_ptr, w_ptr, dx_ptr, B,
                 H: tl.constexpr, W: tl.constexpr, OH: tl.constexpr, OW: tl.constexpr,
                 CIN: tl.constexpr, COUT: tl.constexpr, KH: tl.constexpr, KW: tl.constexpr,
                 STRIDE: tl.constexpr, RELU: tl.constexpr,
                 BLOCK_M: tl.constexpr, BLOCK_N: tl.constexpr, BLOCK_K: tl.constexpr):
    """On activations (the frames need no gradient): dx[run, b, ih, iw, ci] = sum over (kh, kw, co) of
    dy[run, b, oh, ow, co] * w[run, kh, kw, ci, co] where ih = S * oh + kh and iw = S * ow + kw, 0 <= oh < OH,
    0 <= ow < OW. A row is one S x S block of input positions (bh, bw) and a column one (ph, pw, ci) of it,
    ih = S * bh + ph, iw = S * bw + pw: every position of the block meets the same outputs, oh = bh - j and
    ow = bw - l for the taps kh = ph + S * j, kw = pw + S * l, so one load of dy per (j, l) serves all of the
    block's S * S positions (the stride costs no masked work and no re-reading), and dx lands in the input's
    own layout (no space-to-depth copy, no gradient of one). Under RELU, dy is the gradient after the layer's
    ReLU: each element counts where the output y there is positive (ReLU's gradient, read where dy is read
    instead of in a pass of its own)."""
    HB: tl.constexpr = (H + STRIDE - 1) // STRIDE  # blocks along a column and a row
    WB: tl.constexpr = (W + STRIDE - 1) // STRIDE
    TAPS_H: tl.constexpr = KH // STRIDE
    TAPS_W: tl.constexpr = KW // STRIDE
    STEPS: tl.constexpr = (COUT + BLOCK_K - 1) // BLOCK_K
    run = tl.program_id(2).to(tl.int64)
    rows = tl.program_id(0) * BLOCK_M + tl.arange(0, BLOCK_M)
    cols = tl.program_id(1) * BLOCK_N + tl.arange(0, BLOCK_N)
    b = rows // (HB * WB)
    bh = rows // WB % HB
    bw = rows % WB
    row_ok = rows < B * (HB * WB)
    ci = cols % CIN
    ph = cols // CIN // STRIDE
    pw = cols // CIN % STRIDE
    col_ok = cols < STRIDE * STRIDE * CIN
    # dy's offset of (b, bh, bw) as if that output position existed; tap (j, l) reads j * OW + l positions
    # before it, wherever the mask allows.
    dy_row = ((b * OH + bh) * OW + bw).to(tl.int64) * COUT
    dy_run = dy_ptr + (run * B) * (OH * OW * COUT)
    y_run = y_ptr + (run * B) * (OH * OW * COUT)
    w_run = w_ptr + run * (KH * KW * CIN * COUT)
    acc = tl.zeros((BLOCK_M, BLOCK_N), dtype=tl.float32)
    for step in range(0, TAPS_H * TAPS_W * STEPS):
        j = step // STEPS // TAPS_W
        l = step // STEPS % TAPS_W
        chans = step % STEPS * BLOCK_K + tl.arange(0, BLOCK_K)
        chan_ok = chans < COUT
        tap_ok = row_ok & (bh - j >= 0) & (bh - j < OH) & (bw - l >= 0) & (bw - l < OW)
        at = dy_row[:, None] + (chans - (j * OW + l) * COUT)[None, :]
        grad = tl.load(dy_run + at, mask=tap_ok[:, None] & chan_ok[None, :], other=0.0)
        if RELU:
            positive = tl.load(y_run + at, mask=tap_ok[:, None] & chan_ok[None, :], other=0.0) > 0
            grad = tl.where(positive, grad, tl.zeros_like(grad))
        tap = (ph + STRIDE * j) * KW + pw + STRIDE * l
        weight = tl.load(w_run + ((tap * CIN + ci)[None, :] * COUT + chans[:, None]),
                         mask=chan_ok[:, None] & col_ok[None, :], other=0.0)
        acc += tl.dot(grad, weight)
    ih = bh[:, None] * STRIDE + ph[None, :]
    iw = bw[:, None] * STRIDE + pw[None, :]
    dx_at = ((b[:, None] * H + ih) * W + iw).to(tl.int64) * CIN + ci[None, :]
    dx_run = dx_ptr + (run * B) * (H * W * CIN)
    tl.store(dx_run + dx_at, acc.to(dx_ptr.dtype.element_ty),
             mask=row_ok[:, None] & col_ok[None, :] & (ih < H) & (iw < W))


@triton.autotune(configs=_WGRAD_CONFIGS, key=_SHAPE_KEY)
@triton.jit
def wgrad_kernel(x_ptr, dy_ptr, y_ptr, parts_ptr, bias_parts_ptr, B, CHUNK, SPLIT,
                 H: tl.constexpr, W: tl.constexpr, OH: tl.constexpr, OW: tl.constexpr,
                 CIN: tl.constexpr, COUT: tl.constexpr, KH: tl.constexpr, KW: tl.constexpr,
                 STRIDE: tl.constexpr, RELU: tl.constexpr,
                 BLOCK_D: tl.constexpr, BLOCK_N: tl.constexpr, BLOCK_M: tl.constexpr):
    """parts[run, part, kh, kw, ci, co] = sum over m in the part's CHUNK rows of x[image, S * oh + kh, S * ow +
    kw, ci] * dy[run, m, co] (the image and x's reading as in forward_kernel), and bias_parts[run, part, co] =
    the sum of those dy[run, m, co]. A program owns BLOCK_D of the KH * KW * CIN filter taps (kh, kw, ci) in
    their flat order (axis 0; as few blocks as possible, since each re-reads dy and y), BLOCK_N output channels
    (axis 1) and one (run, part) (axis 2):
    SPLIT parts per run spread M's up to 2 M rows over the GPU, each writing fp32 partial sums that the caller
    adds up; the programs of the first (kh, kw, ci) block also sum dy for the bias, on the tiles they load
    anyway. Under RELU, dy counts where the output y is positive (as in dgrad_kernel)."""
    taps = tl.program_id(0) * BLOCK_D + tl.arange(0, BLOCK_D)
    taps_ok = taps < KH * KW * CIN
    # A tap's offset from an output position's top-left input element: row kh, then KW * CIN contiguous.
    tap_at = taps // (KW * CIN) * (W * CIN) + taps % (KW * CIN)
    cols = tl.program_id(1) * BLOCK_N + tl.arange(0, BLOCK_N)
    col_ok = cols < COUT
    run = (tl.program_id(2) // SPLIT).to(tl.int64)
    part = tl.program_id(2) % SPLIT
    m_total = B * (OH * OW)
    start = part * CHUNK
    end = tl.minimum(start + CHUNK, m_total)
    dy_run = dy_ptr + (run * B) * (OH * OW * COUT)
    y_run = y_ptr + (run * B) * (OH * OW * COUT)
    sums_bias = tl.program_id(0) == 0
    acc = tl.zeros((BLOCK_D, BLOCK_N), dtype=tl.float32)
    bias_acc = tl.zeros((BLOCK_N,), dtype=tl.float32)
    for m0 in range(start, end, BLOCK_M):
        rows = m0 + tl.arange(0, BLOCK_M)
        row_ok = rows < end
        b = rows // (OH * OW)
        oh = rows // OW % OH
        ow = rows % OW
        x_row = (((run * B + b) * H + oh * STRIDE) * W + ow * STRIDE) * CIN
        patch = tl.load(x_ptr + (x_row[:, None] + tap_at[None, :]), mask=row_ok[:, None] & taps_ok[None, :],
                        other=0).to(dy_ptr.dtype.element_ty)
        at = rows.to(tl.int64)[:, None] * COUT + cols[None, :]
        grad = tl.load(dy_run + at, mask=row_ok[:, None] & col_ok[None, :], other=0.0)
        if RELU:
            positive = tl.load(y_run + at, mask=row_ok[:, None] & col_ok[None, :], other=0.0) > 0
            grad = tl.where(positive, grad, tl.zeros_like(grad))
        acc += tl.dot(tl.trans(patch), grad)
        if sums_bias:
            bias_acc += tl.sum(grad.to(tl.float32), axis=0)
    parts_run = parts_ptr + tl.program_id(2).to(tl.int64) * (KH * KW * CIN * COUT)
    tl.store(parts_run + (taps[:, None] * COUT + cols[None, :]), acc, mask=taps_ok[:, None] & col_ok[None, :])
    if sums_bias:
        tl.store(bias_parts_ptr + tl.program_id(2).to(tl.int64) * COUT + cols, bias_acc, mask=col_ok)


def _width_block(channels: int) -> int:
    """A tile width covering up to 64 channels (tl.dot needs at least 16)."""
    return max(16, min(64, triton.next_power_of_2(channels)))


def _wgrad_chunk(m: int, runs: int) -> int:
    """Rows of M each weight-gradient program sums: about 512 (run, part) programs in all fill the GPU, and at
    least 2,048 rows each keep the fp32 partial sums small against the work."""
    return max(2048, triton.cdiv(triton.cdiv(m, max(1, 512 // runs)), 128) * 128)


def _shape_args(h: int, w: int, kh: int, kw: int, cin: int, cout: int, stride: int, relu: bool) -> dict:
    """The shape constants every kernel takes, for an input of h x w x cin."""
    return dict(H=h, W=w, OH=(h - kh) // stride + 1, OW=(w - kw) // stride + 1, CIN=cin, COUT=cout, KH=kh, KW=kw,
                STRIDE=stride, RELU=relu)


def _forward(x: torch.Tensor, w: torch.Tensor, bias: torch.Tensor, stride: int, relu: bool) -> torch.Tensor:
    """x [K, B, H, W, Cin] in w's dtype or uint8; w [K, kh, kw, Cin, Cout], bias [K * Cout] fp32 -> [K, B, OH,
    OW, Cout] in w's dtype (through a ReLU under `relu`)."""
    k, b = x.shape[:2]
    _, kh, kw, _, cout = w.shape
    shape = _shape_args(*x.shape[-3:-1], kh, kw, x.shape[-1], cout, stride, relu)
    y = torch.empty((k, b, shape["OH"], shape["OW"], cout), device=x.device, dtype=w.dtype)
    block_n = _width_block(cout)
    grid = lambda meta: (triton.cdiv(b * shape["OH"] * shape["OW"], meta["BLOCK_M"]), triton.cdiv(cout, block_n), k)
    forward_kernel[grid](x, w, bias, y, b, **shape, BLOCK_N=block_n)
    return y


def _dgrad(dy: torch.Tensor, y: torch.Tensor, w: torch.Tensor, h: int, wd: int, stride: int,
           relu: bool) -> torch.Tensor:
    """dy and the output y [K, B, OH, OW, Cout], w [K, kh, kw, Cin, Cout] (dy's dtype) -> dx [K, B, H, W, Cin]
    (the stride dividing the kernel); under `relu`, dy is taken where y > 0 only."""
    k, b, _, _, cout = dy.shape
    _, kh, kw, cin, _ = w.shape
    dx = torch.empty((k, b, h, wd, cin), device=dy.device, dtype=dy.dtype)
    blocks = b * triton.cdiv(h, stride) * triton.cdiv(wd, stride)  # stride x stride blocks of input positions
    grid = lambda meta: (triton.cdiv(blocks, meta["BLOCK_M"]), triton.cdiv(stride * stride * cin, meta["BLOCK_N"]), k)
    dgrad_kernel[grid](dy, y, w, dx, b, **_shape_args(h, wd, kh, kw, cin, cout, stride, relu))
    return dx


def _wgrad(x: torch.Tensor, dy: torch.Tensor, y: torch.Tensor, kh: int, kw: int, stride: int,
           relu: bool) -> Tuple[torch.Tensor, torch.Tensor]:
    """x as _forward takes it, dy and the output y [K, B, OH, OW, Cout] (the compute dtype) -> dw [K, kh, kw, Cin,
    Cout] and db [K, Cout] in fp32; under `relu`, dy is taken where y > 0 only."""
    k, b, oh, ow, cout = dy.shape
    cin = x.shape[-1]
    chunk = _wgrad_chunk(b * oh * ow, k)
    split = triton.cdiv(b * oh * ow, chunk)
    parts = torch.empty((k, split, kh, kw, cin, cout), device=x.device, dtype=torch.float32)
    bias_parts = torch.empty((k, split, cout), device=x.device, dtype=torch.float32)
    block_n = _width_block(cout)
    grid = lambda meta: (triton.cdiv(kh * kw * cin, meta["BLOCK_D"]), triton.cdiv(cout, block_n), k * split)
    wgrad_kernel[grid](x, dy, y, parts, bias_parts, b, chunk, split,
                       **_shape_args(*x.shape[-3:-1], kh, kw, cin, cout, stride, relu), BLOCK_N=block_n)
    return parts.sum(dim=1), bias_parts.sum(dim=1)


def frames_to_blocks(frames: torch.Tensor, images: torch.Tensor, s: int) -> torch.Tensor:
    """uint8 frames [..., H, W, C] at int64 images [K, B] -> [K, B, H // s, W // s, C * s * s] uint8: run k's
    b-th frame, frames.reshape(-1, H, W, C)[images[k, b]], cut into s x s blocks whose channel (c, p, q) holds
    pixel (s * i + p, s * j + q) channel c of block (i, j) (space_to_depth.weight_space_to_depth's order). One
    pass: the gather and the rearrangement together. Rows and columns past the last whole block are dropped
    (a convolution whose kernel and stride are multiples of s never reads them)."""
    h, w, c = frames.shape[-3:]
    k, b = images.shape
    blocks = torch.empty((k, b, h // s, w // s, c * s * s), device=frames.device, dtype=torch.uint8)
    strip = w // s * s * s * c
    blocks_kernel[(k * b, h // s)](frames, images, blocks, H=h, W=w, C=c, S=s,
                                   BLOCK=triton.next_power_of_2(strip))
    return blocks


class _PackedConv(torch.autograd.Function):
    """The unpadded packed convolution, with its ReLU under `relu`, of x [K, B, H, W, Cin] (bf16 or fp32, or
    uint8 read as the integers it holds), at a stride that divides the kernel; the grouped layout's weight [K * Cout, Cin, kh, kw] and bias [K * Cout] (any float dtype) -> [K, B, OH,
    OW, Cout] in `dtype`. The kernels compute in `dtype` with fp32 sums (fp32 master weights arrive as they are
    under autocast: cast here); the gradients come back in their inputs' dtypes. The ReLU is the forward
    kernel's epilogue, and its gradient is applied where the backward kernels read the incoming gradient: no
    pass of its own either way."""

    @staticmethod
    def forward(ctx, x, weight, bias, stride, dtype, relu):
        k = x.shape[0]
        cin = x.shape[-1]
        cout, kh, kw = weight.shape[0] // k, weight.shape[2], weight.shape[3]
        assert weight.shape[1] == cin and weight.shape[0] == k * cout, (x.shape, weight.shape)
        assert kh % stride == 0 and kw % stride == 0, (weight.shape, stride)
        x = x.contiguous()
        w = weight.reshape(k, cout, cin, kh, kw).permute(0, 3, 4, 2, 1).contiguous().to(dtype)
        y = _forward(x, w, bias.to(torch.float32).contiguous(), stride, relu)
        ctx.save_for_backward(x, w, y)
        ctx.stride, ctx.relu, ctx.weight_dtype, ctx.bias_dtype = stride, relu, weight.dtype, bias.dtype
        return y

    @staticmethod
    def backward(ctx, dy):
        x, w, y = ctx.saved_tensors
        k, kh, kw, cin, cout = w.shape
        dy = dy.to(y.dtype).contiguous()
        dx = dw = db = None
        if ctx.needs_input_grad[0]:  # activations only: frames are integers
            dx = _dgrad(dy, y, w, x.shape[2], x.shape[3], ctx.stride, ctx.relu)
        if ctx.needs_input_grad[1] or ctx.needs_input_grad[2]:
            dw, db = _wgrad(x, dy, y, kh, kw, ctx.stride, ctx.relu)
            dw = dw.permute(0, 4, 3, 1, 2).reshape(k * cout, cin, kh, kw).to(ctx.weight_dtype)
            db = db.reshape(-1).to(ctx.bias_dtype)
        return dx, dw, db, None, None, None


def packed_conv(x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor, stride: int = 1,
                relu: bool = False) -> torch.Tensor:
    """K runs' unpadded convolutions at once: x [K, B, H, W, Cin], weight [K * Cout, Cin, kh, kw] and bias
    [K * Cout] as nn.Conv2d(groups=K) holds them -> [K, B, OH, OW, Cout], through a ReLU under `relu`
    (F.relu(packed_conv(...)) without the ReLU's passes). The stride must divide the kernel; the kernels stride
    over x as it lies."""
    return _PackedConv.apply(x, weight, bias, stride, x.dtype, relu)


def packed_conv_frames(frames: torch.Tensor, images: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor,
                       stride: int, dtype: torch.dtype, relu: bool = False) -> torch.Tensor:
    """packed_conv of K runs' uint8 frames / 255 in `dtype`, where run k's b-th frame is frames.reshape(-1, H,
    W, C)[images[k, b]] (the rollout buffer and a minibatch's indices, or a batch [K, B, H, W, C] and
    torch.arange(K * B).view(K, B)). It runs as the equal stride-1 convolution over the frames' stride x stride
    blocks (frames_to_blocks: one uint8 copy) with the blocks' weight / 255: the kernels read the bytes as exact
    integers, so the only rounding is the weight's to `dtype`, as autocast's, and not also the frames' / 255.
    The frames get no gradient."""
    assert frames.dtype == torch.uint8 and images.dtype == torch.int64 and images.dim() == 2, (frames.dtype,
                                                                                               images.shape)
    blocks = frames_to_blocks(frames.contiguous(), images.contiguous(), stride)
    return _PackedConv.apply(blocks, weight_space_to_depth(weight, stride) / 255.0, bias, 1, dtype, relu)
