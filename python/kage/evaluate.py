"""`python3 -m kage.evaluate` moved: scoring configs to `python3 -m kage.ppo.evaluate`, scoring a suite
(--suite) to `python3 -m kage.bench score`; this forwards."""
import sys

if __name__ == "__main__":
    if any(a == "--suite" or a.startswith("--suite=") for a in sys.argv[1:]):
        from kage.bench import score as moved
        new = "python3 -m kage.bench score"
    else:
        from kage.ppo import evaluate as moved
        new = "python3 -m kage.ppo.evaluate"
    print(f"kage.evaluate: moved to `{new}`; this old name forwards to it for now", file=sys.stderr)
    sys.exit(moved.main())
