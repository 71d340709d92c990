"""Teach a fact-bottleneck PrediNet (ModelConfig.relation_bits) a trained agent's policy: DAgger
with the trained network as the teacher, for envs without a planner (Box-World).

    python experiments/bottleneck_distill.py checkpoints/bw2-predinet.pt runs/bw2-facts.pt \
        --minutes 30 [--tau 0.25] [--envs 16] [--lr 5e-4]

The student starts from the teacher's weights with a fresh read-out (experiments/
bottleneck_init.py). Its own sampled actions drive the episodes (the teacher's instead with a
chance that falls from 1 to 0 over ``--beta-frames``); every visited state is labelled with the
teacher's action probabilities and value, and the student is fitted on a ring of the latest
states: KL(teacher || student) plus the value's squared error. Prints the student's training
success every ~10 s and writes the student as a checkpoint (its card: held-out eval).
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from dataclasses import replace

import numpy as np
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import read_checkpoint, save_checkpoint
from neurosym.agent.learners.imitation import expert_share
from neurosym.agent.networks.model import ActorCritic
from neurosym.envs import make_batched


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("teacher")
    parser.add_argument("out")
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--tau", type=float, default=0.25)
    parser.add_argument("--envs", type=int, default=16)
    parser.add_argument("--n-steps", type=int, default=16)
    parser.add_argument("--batch", type=int, default=512)
    parser.add_argument("--updates", type=int, default=8, help="minibatches per rollout")
    parser.add_argument("--buffer", type=int, default=200_000)
    parser.add_argument("--beta-frames", type=int, default=200_000)
    parser.add_argument("--lr", type=float, default=5e-4)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--student", help="continue this earlier student (its weights) instead")
    args = parser.parse_args()
    torch.set_num_threads(1)
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    teacher = load_agent(args.teacher)
    source = read_checkpoint(args.teacher)
    config = replace(source["model_config"], relation_bits=args.tau)
    student = ActorCritic(config)
    state = student.state_dict()
    state.update(
        {
            k: v.float()
            for k, v in source["state_dict"].items()
            if not k.startswith("relational.out.")
        }
    )
    history = source.get("command")
    if args.student:
        earlier = read_checkpoint(args.student)
        state.update({k: v.float() for k, v in earlier["state_dict"].items()})
        history = earlier.get("command")
    student.load_state_dict(state)
    opt = torch.optim.Adam(student.parameters(), lr=args.lr)
    venv = make_batched(teacher.env_name, args.envs, seed=args.seed, **teacher.env_kwargs)
    obs, _ = venv.reset(seed=args.seed)
    ring_obs = np.zeros((args.buffer, *obs.shape[1:]), dtype=obs.dtype)
    ring_p = np.zeros((args.buffer, int(venv.single_action_space.n)), dtype=np.float32)
    ring_v = np.zeros(args.buffer, dtype=np.float32)
    size = nxt = frames = 0
    if args.student:
        frames = int(earlier.get("frames", 0))  # beta goes on from there
    done_eps: list[bool] = []
    start = last = time.monotonic()
    while time.monotonic() - start < args.minutes * 60:
        beta = expert_share(frames, args.beta_frames)
        for _ in range(args.n_steps):
            x = torch.from_numpy(obs)
            with torch.no_grad():
                t_logits, t_value = teacher.model(x)
                s_logits, _ = student(x)
            probs = torch.softmax(t_logits, -1).numpy()
            idx = (nxt + np.arange(len(obs))) % args.buffer
            ring_obs[idx], ring_p[idx], ring_v[idx] = obs, probs, t_value.numpy()
            nxt = int((nxt + len(obs)) % args.buffer)
            size = min(size + len(obs), args.buffer)
            mine = torch.distributions.Categorical(logits=s_logits).sample().numpy()
            theirs = probs.argmax(1)
            actions = np.where(rng.random(len(obs)) < beta, theirs, mine)
            obs, reward, terminated, truncated, _ = venv.step(actions)
            obs = np.ascontiguousarray(obs)
            frames += len(obs)
            for i in np.flatnonzero(terminated | truncated):
                done_eps.append(bool(terminated[i] and reward[i] > 0))
        for _ in range(args.updates):
            b = rng.integers(0, size, args.batch)
            logits, value = student(torch.from_numpy(ring_obs[b]))
            target = torch.from_numpy(ring_p[b])
            kl = (
                (target * (torch.log(target.clamp_min(1e-8)) - torch.log_softmax(logits, -1)))
                .sum(-1)
                .mean()
            )
            loss = kl + 0.5 * (value - torch.from_numpy(ring_v[b])).pow(2).mean()
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(student.parameters(), 1.0)
            opt.step()
        if time.monotonic() - last > 10:
            recent = done_eps[-100:]
            print(
                f"{time.monotonic() - start:7.0f} s {frames:9d} frames beta {beta:.2f} kl {kl.item():.4f} "
                f"success(last {len(recent)}) {np.mean(recent) if recent else float('nan'):.2f}",
                flush=True,
            )
            last = time.monotonic()
    command = " && ".join(filter(None, [
        history,
        "python " + " ".join(shlex.quote(a) for a in ["experiments/bottleneck_distill.py", *sys.argv[1:]]),
    ]))  # fmt: skip
    save_checkpoint(args.out, model=student, config=config, env_name=teacher.env_name,
                    env_kwargs=teacher.env_kwargs, frames=frames, command=command)  # fmt: skip
    print(f"wrote {args.out}: {frames} frames")


if __name__ == "__main__":
    main()
