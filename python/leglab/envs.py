"""Gymnasium-style environments on leglab's plants (written next)."""
