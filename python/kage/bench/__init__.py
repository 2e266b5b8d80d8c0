"""kage.bench: run a suite of training runs and report the benchmark's tables and plots."""
