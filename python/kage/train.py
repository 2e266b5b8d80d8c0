"""`python3 -m kage.train` moved to `python3 -m kage.ppo.train` (the PPO baseline's package); this forwards."""
import sys

if __name__ == "__main__":
    from kage.ppo import train

    print("kage.train: moved to `python3 -m kage.ppo.train`; this old name forwards to it for now", file=sys.stderr)
    sys.exit(train.main())
