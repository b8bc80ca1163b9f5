"""Drivers: march contact laws over prescribed histories."""

from ._csv import read_pair_history_csv
from ._march import march
from .interface_loop import InterfaceLoopResult, InterfaceLoopStatus, interface_loop
from .quasistatic import LoopResult, LoopStatus, cycle_count, harmonic_history, harmonic_loop, quasistatic, read_history_csv

__all__ = ["march", "quasistatic", "harmonic_loop", "harmonic_history", "read_history_csv", "read_pair_history_csv",
           "cycle_count", "LoopResult",
           "LoopStatus", "interface_loop", "InterfaceLoopResult", "InterfaceLoopStatus"]
