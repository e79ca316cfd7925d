"""Discrepancy workflow: locate, name and add missing physical effects."""
