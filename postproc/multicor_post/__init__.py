"""Post-processing of MULTICOR results files (HDF5 layout: doc/output.md)."""
from .results import (THETA, U, W, Dynamic, Energy, Mesh, Modal, Records, Results, ResultsError,
                      Static, load_results)

__all__ = ["load_results", "Results", "ResultsError", "Records", "Mesh", "Dynamic", "Energy",
           "Static", "Modal", "U", "W", "THETA"]
