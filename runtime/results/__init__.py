"""Results: the SimulationResult, its summary and the paper's figures."""
