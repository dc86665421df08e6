"""Solving: run settings, the integration engines, the run loop, its checks and failure diagnosis."""
