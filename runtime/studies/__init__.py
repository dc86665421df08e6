"""Studies that reuse the simulator: preload design, sweeps."""
