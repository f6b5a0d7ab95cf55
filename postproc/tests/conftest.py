"""Fixtures of the post-processing tests; makes postproc/ importable (multicor_post,
plot_beam) when pytest runs from the repository root."""
import contextlib
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


@pytest.fixture
def drawing_only(monkeypatch):
    """Context manager for a test of what a plotting script says or returns: inside
    ``with drawing_only(*names) as skipped:``, the scripts draw and write only the figure
    files named (none without a name), inside ``with drawing_only(all_but=names)`` every
    figure file but those named; each other figure is built as without it but not drawn, and
    the path it would have been written to is appended to ``skipped``.

    Drawing a figure (constrained layout, then rendering and PNG encoding) costs about 0.3
    CPU-s: most of this suite's time. A test uses it only for figures that another test
    draws and writes byte for byte the same (the same synthetic data and the same options
    that shape them), named in a comment at each use; the scripts' own logic (loading,
    building every figure, the paths printed, notes, exit codes) runs as without it. A check
    that a figure is not written looks in ``skipped`` as well as on disk."""
    import plot_experiments
    from multicor_post import results

    @contextlib.contextmanager
    def drawing(*names, all_but=None):
        assert not (names and all_but is not None)
        skipped = []
        draw = results.save_figure

        def save_figure(fig, path, dpi):
            name = os.path.basename(os.fspath(path))
            if (name not in all_but) if all_but is not None else (name in names):
                draw(fig, path, dpi)
            else:
                skipped.append(os.fspath(path))

        with monkeypatch.context() as patch:
            # FigureFiles.save calls results.save_figure; plot_experiments imported it by name
            patch.setattr(results, "save_figure", save_figure)
            patch.setattr(plot_experiments, "save_figure", save_figure)
            yield skipped
    return drawing
