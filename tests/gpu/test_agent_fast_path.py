"""The whole network under the fast flags (--bf16 --fused-input --triton-conv: the Triton torso on 4 x 4 blocks,
conv3's output in (row, column, channel) order against fc_weight's rows reordered to match) against the float32
default (cuDNN on the frames), on the GPU with the same parameters, on a batch and on a minibatch read from a
rollout buffer. The logits, the values and every parameter's gradient must be as close to float32's as those of
the same network under --bf16 alone (cuDNN under bf16 autocast) are, within SLACK: the fast path changes no
more than bf16 autocast already does. Errors are max |got - want| / max |want|; each is printed."""
import torch
from test_triton_conv import relative_error

from kage.ppo.agent import Agent
from kage.ppo.policy import autocast

SLACK = 1.5  # whole-network errors compound each layer's rounding, which the per-layer test bounds by 1.1


def outputs(agent, inputs, bf16: bool, weights):
    with autocast(bf16):
        logits, value = agent(*inputs)
    loss = (logits.float() * weights).sum() + value.float().square().sum()
    grads = torch.autograd.grad(loss, list(agent.parameters()))
    names = ["logits", "values"] + [name for name, _ in agent.named_parameters()]
    return dict(zip(names, [logits, value, *grads]))


def test_fast_agent_is_as_close_to_float32_as_autocast():
    torch.backends.cudnn.allow_tf32 = False
    torch.backends.cuda.matmul.allow_tf32 = False
    device, seeds, batch = torch.device("cuda"), [3, 4, 5], 64
    plain = Agent(seeds, device=device)
    autocast_only = Agent(seeds, device=device, bf16=True)
    fast = Agent(seeds, device=device, bf16=True, fused_input=True, triton_conv=True)
    generator = torch.Generator(device).manual_seed(0)
    buffer = torch.randint(0, 256, (2, len(seeds), batch, 128, 128, 3), dtype=torch.uint8, device=device,
                           generator=generator)
    images = torch.randperm(2 * len(seeds) * batch, device=device, generator=generator)[:len(seeds) * batch]
    images = images.view(len(seeds), batch)
    obs = buffer.view(-1, 128, 128, 3)[images]
    weights = torch.randn(len(seeds), batch, 8, device=device, generator=generator)
    want = outputs(plain, (obs,), False, weights)
    bound = {n: relative_error(g, want[n]) for n, g in outputs(autocast_only, (obs,), True, weights).items()}
    failures = []
    for label, inputs in (("batch", (obs,)), ("minibatch in place", (buffer, images))):
        for name, got in outputs(fast, inputs, True, weights).items():
            error = relative_error(got, want[name])
            print(f"{label} {name}: fast {error:.2e}, autocast {bound[name]:.2e}")
            if error > SLACK * bound[name]:
                failures.append((label, name, error, bound[name]))
    assert not failures
