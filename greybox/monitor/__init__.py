"""Friction fingerprints from production logs, their history (Parquet), change detection and the dashboard."""
