"""Helpers every layer uses: atomic file writes, signal handling for child processes, text tables."""
