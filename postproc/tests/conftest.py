"""Fixtures of the post-processing tests; makes postproc/ importable (multicor_post,
plot_beam) when pytest runs from the repository root."""
import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from synthetic import cantilever_layout, write_results  # noqa: E402


@pytest.fixture
def cantilever_file(tmp_path):
    """Factory: write a synthetic cantilever results file and return its path."""
    def make(name="cantilever.h5", angle=0.0, **kwargs):
        ids, xy, conn, d = cantilever_layout(angle=angle)
        return write_results(tmp_path / name, ids, xy, conn, d, **kwargs)
    return make
