"""Drivers: march contact laws over prescribed histories."""

from ._march import march

__all__ = ["march"]
