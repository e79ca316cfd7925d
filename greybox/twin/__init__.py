"""Synthetic machine-tool feed axis: truth plant, trajectories, hidden effects."""
