"""PPO's arithmetic (kage-ppo-baseline.md §2.5 step 3, §2.6), with any leading run axes: GAE, the clipped
losses, the entropy coefficient and the per-run gradient clip; and DrAC's regularisers (--augment-mode drac)."""
import torch


def compute_gae(rewards, values, dones, next_value, next_done, gamma: float, gae_lambda: float):
    """Advantages and returns over a [T, ...] rollout (§2.5 step 3). dones[t] is true iff obs[t] starts an
    episode; next_done / next_value belong to the observation after the last step."""
    num_steps = rewards.shape[0]
    advantages = torch.zeros_like(rewards)
    last_gae = torch.zeros_like(next_value)
    for t in reversed(range(num_steps)):
        if t == num_steps - 1:
            nonterminal, next_values = 1.0 - next_done, next_value
        else:
            nonterminal, next_values = 1.0 - dones[t + 1], values[t + 1]
        delta = rewards[t] + gamma * next_values * nonterminal - values[t]
        last_gae = delta + gamma * gae_lambda * nonterminal * last_gae
        advantages[t] = last_gae
    return advantages, advantages + values


def ppo_loss(new_logprob, entropy, new_value, old_logprob, old_value, advantages, returns, args, ent_coef: float):
    """The minibatch loss of §2.6 and its diagnostics, reduced over the last axis (a run's minibatch):
    (loss, pg_loss, v_loss, entropy, approx_kl, clipfrac), each [K] (or a scalar without a run axis)."""
    logratio = new_logprob - old_logprob
    ratio = logratio.exp()
    with torch.no_grad():
        approx_kl = ((ratio - 1) - logratio).mean(-1)
        clipfrac = ((ratio - 1.0).abs() > args.clip_coef).float().mean(-1)
    if args.norm_adv:
        # Population standard deviation (divide by n), as the original's jnp.std.
        mean = advantages.mean(-1, keepdim=True)
        advantages = (advantages - mean) / (advantages.std(-1, unbiased=False, keepdim=True) + 1e-8)
    pg_loss = torch.max(-advantages * ratio, -advantages * ratio.clamp(1 - args.clip_coef, 1 + args.clip_coef)).mean(-1)
    if args.clip_vloss:
        v_clipped = old_value + (new_value - old_value).clamp(-args.clip_coef, args.clip_coef)
        v_loss = 0.5 * torch.max((new_value - returns) ** 2, (v_clipped - returns) ** 2).mean(-1)
    else:
        v_loss = 0.5 * ((new_value - returns) ** 2).mean(-1)
    entropy_loss = entropy.mean(-1)
    loss = pg_loss - ent_coef * entropy_loss + v_loss * args.vf_coef
    return loss, pg_loss, v_loss, entropy_loss, approx_kl, clipfrac


def drac_regularisers(logits, value, augmented_logits, augmented_value, var_returns):
    """DrAC's regularisers (Raileanu et al. 2021, eq. 4-5), each [K] (a mean over the last axis): G_pi =
    KL(pi(.|s) || pi(.|aug(s))) and G_V = (V(s) - V(aug(s)))^2 / var_returns, the plain frames' policy and value
    held fixed, so that the gradient pulls the augmented frames' outputs towards the plain ones (as DrAC's code,
    which takes them from the rollout without a gradient). The KL is exact over the actions, not sampled.

    G_V is measured in units of the returns' standard deviation (var_returns [K]: each run's over its batch): DrAC's
    Procgen runs, whose alpha_r = 0.1 this keeps, normalised rewards by the returns' running standard deviation
    (VecNormalize), so their values were in those units. KAGE's returns run to thousands without normalisation,
    and the raw squared difference then outweighed PPO's own terms and collapsed every seed of IMAGE_SKELETON with
    colour jitter to a deterministic policy within 40 iterations (lab/2026-11-27-h100-augmentation)."""
    log_p = torch.log_softmax(logits.detach(), dim=-1)
    log_q = torch.log_softmax(augmented_logits, dim=-1)
    policy = (log_p.exp() * (log_p - log_q)).sum(-1).mean(-1)
    value = ((value.detach() - augmented_value) ** 2).mean(-1) / (var_returns + 1e-8)
    return policy, value


def entropy_coefficient(args, optimizer_steps: int) -> float:
    """§2.6: constant, or annealed from the optimiser steps taken so far."""
    if not args.ent_coef_anneal:
        return args.ent_coef
    total = args.num_iterations * args.update_epochs * args.num_minibatches
    return args.ent_coef * min(max(1.0 - optimizer_steps / total, 0.0), 1.0)


def clip_grad_norm_per_run(agent, max_norm: float) -> torch.Tensor:
    """Scales each run's gradients by max_norm / max(norm, max_norm), its norm taken over all its
    parameters (Optax's clip_by_global_norm, §2.1); returns the [K] norms."""
    grads = [agent.run_view(p.grad) for p in agent.parameters()]
    # Each parameter's per-run norm in one reading pass (no squared copy), then their root sum of squares.
    norm = torch.stack([torch.linalg.vector_norm(g, dim=tuple(range(1, g.dim()))) for g in grads]).norm(dim=0)
    scale = max_norm / torch.maximum(norm, torch.full_like(norm, max_norm))
    for g in grads:
        g.mul_(scale.view(-1, *[1] * (g.dim() - 1)))
    return norm


def entropy_of(logits: torch.Tensor) -> torch.Tensor:
    """Entropy from log-softmax logits clipped at the smallest float32, so p log p is never 0 * -inf."""
    log_p = torch.log_softmax(logits, dim=-1).clamp(min=torch.finfo(logits.dtype).min)
    return -(log_p.exp() * log_p).sum(-1)
