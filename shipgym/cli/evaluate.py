"""``shipgym evaluate``: a controller or agent on one env, episodes as batched rollouts."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym.cli._common import (
    MAX_EPISODES,
    MAX_SEED,
    PROG,
    float_in,
    int_in,
    model_name,
    output_dir,
    output_path,
    write_outputs,
)
from shipgym.cli._ray import add_ray_flags, campaign_failed, ray_options


def run(args: argparse.Namespace) -> int:
    import json

    from shipgym.benchmark import evaluate, make_policy
    from shipgym.benchmark.evaluate import BLOW_UP, EpisodeError
    from shipgym.benchmark.plots import episode_figures
    from shipgym.cluster import ClusterTaskError

    json_path = output_path(args.json, "--json", ".json")
    plot_dir = None if args.plot is None else output_dir(args.plot, "--plot")
    ray = ray_options(args)
    if args.gains is not None:
        from shipgym.benchmark.policies import GAINS_ENV

        if args.controller != "classic" or args.env != GAINS_ENV:
            raise ValueError(
                f"--gains sets the classic heading autopilot of {GAINS_ENV}: use it with "
                f"--env {GAINS_ENV} --controller classic, not --env {args.env} --controller "
                f"{args.controller}"
            )
        if ray is not None:
            raise ValueError("--gains runs the episodes here; drop --ray")
    env_kwargs: dict[str, Any] = {}
    if args.max_current_speed is not None:
        env_kwargs["max_current_speed"] = args.max_current_speed
    if args.model is not None:
        from shipgym.benchmark.policies import GAINS_ENV

        if args.env != GAINS_ENV:
            raise ValueError(
                f"--model sets the ship of {GAINS_ENV} (a Nomoto-family model or an identified "
                f"model file); {args.env} sails its own ship"
            )
        env_kwargs["model"] = args.model
    policy = make_policy(args.controller, args.env, args.agents, gains=args.gains, model=args.model)
    if hasattr(policy, "meta"):
        from shipgym.benchmark.runner import check_seeds_disjoint

        try:
            check_seeds_disjoint(policy.meta, args.seed, args.episodes)
        except ValueError as exc:
            print(f"{PROG}: warning: {exc}", file=sys.stderr)
    try:
        if ray is None:
            result = evaluate(
                args.env,
                policy,
                args.controller,
                episodes=args.episodes,
                seed=args.seed,
                env_kwargs=env_kwargs,
            )
        else:
            from shipgym.benchmark.runner import evaluate_on_ray

            address, cpus, task_size = ray
            result = evaluate_on_ray(
                args.env,
                args.controller,
                args.episodes,
                args.seed,
                address=address,
                num_cpus=cpus,
                task_size=task_size,
                env_kwargs=env_kwargs,
                agents_dir=args.agents,
                keep_logs=None if plot_dir is not None else 0,
                design_model=args.model,
            )
    except (EpisodeError, ClusterTaskError) as exc:
        return campaign_failed(exc)
    summary = result.to_dict()
    print(
        f"{args.env} controller {args.controller}: {args.episodes} episodes from seed {args.seed}"
    )
    if result.blown_up:
        ends = zip(result.lengths, result.terminations, strict=True)
        steps = [n for n, reason in ends if reason == BLOW_UP]
        print(
            f"  BLEW UP: {result.blown_up} of {args.episodes} episodes ended in a numerical "
            f"blow-up (at steps {', '.join(map(str, steps[:10]))}"
            f"{', ...' if len(steps) > 10 else ''}); return and metrics undefined"
        )
    else:
        print(f"  return {summary['mean_return']:.2f} +- {summary['std_return']:.2f}")
        for key, value in summary["metrics"].items():
            print(f"  {key:22s} {value:10.3f} +- {summary['metrics_std'][key]:.3f}")
    outputs: list[tuple[Path, Callable[[Path], Any]]] = []
    if json_path is not None:
        outputs.append((json_path, lambda p: p.write_text(json.dumps(summary, indent=2) + "\n")))
    if plot_dir is not None:
        outputs += episode_figures(result, plot_dir, max_episodes=args.episodes)
    write_outputs(outputs)
    return 0


def build(sub: Any) -> None:
    from shipgym.benchmark.policies import POLICIES
    from shipgym.envs import ENV_IDS
    from shipgym.rl.train import BENCHMARK_SEED

    p = sub.add_parser(
        "evaluate",
        help="run a controller on an env over seeded episodes and report the task metrics",
        description=(
            "Run the classic controller, a trained PPO or SAC agent or the zero command on an "
            "env for N episodes with seeds S, S+1, ... (identical initial states, setpoints, "
            "paths, targets and currents for every controller) and print the mean return and "
            "the task metrics."
        ),
    )
    p.add_argument(
        "--env", required=True, choices=ENV_IDS, help="the environment id (shipgym envs lists them)"
    )
    p.add_argument(
        "--controller",
        default="classic",
        choices=POLICIES,
        help="the policy: the classic controller (design-rule or tuned gains), a shipped agent "
        "or the zero command (default: %(default)s)",
    )
    p.add_argument(
        "--episodes",
        type=int_in(1, MAX_EPISODES),
        default=10,
        metavar="N",
        help="episodes, seeds S, S+1, ... (default: %(default)s)",
    )
    p.add_argument(
        "--seed",
        type=int_in(0, MAX_SEED),
        default=BENCHMARK_SEED,
        metavar="S",
        help="first seed; the default is the benchmark's, outside every agent's training and "
        "validation seeds and the tuned gains' seeds, so a cell of the benchmark is reproduced "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--agents",
        default=None,
        metavar="DIR",
        help="folder of the ppo/sac agents (default: the agents shipped with shipgym)",
    )
    p.add_argument(
        "--max-current-speed",
        type=float_in(0.0, 5.0, "m/s"),
        default=None,
        metavar="M_S",
        help="upper end of the drawn current speed [m/s] (default: the env's)",
    )
    p.add_argument(
        "--gains",
        default=None,
        metavar="FILE",
        help="gains of the classic NomotoHeading autopilot (shipgym design MODEL.json --json "
        "FILE) instead of the design rule on the nominal ship",
    )
    p.add_argument(
        "--model",
        default=None,
        type=model_name,
        metavar="NAME|FIT.json",
        help="the ship of shipgym/NomotoHeading-v0: a Nomoto-family model or an identified "
        "model file (shipgym identify --json FIT.json); the classic controllers are designed "
        "on it (default: the env's)",
    )
    p.add_argument("--json", default=None, metavar="OUT", help="write the summary as JSON")
    p.add_argument(
        "--plot", default=None, metavar="DIR", help="write a figure per episode into DIR"
    )
    add_ray_flags(p, "episodes")
    p.set_defaults(handler=run)
