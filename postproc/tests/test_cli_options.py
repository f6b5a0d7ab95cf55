"""Command-line options and output folders of the plotting scripts: a value that cannot give a
meaningful figure, a folder that cannot be written and a file of the wrong kind end with a
one-line message (usage errors exit 2, file errors exit 1), never a traceback and never a
figure saved with exit 0."""
import pytest
from synthetic_coupled import write_coupled

import plot_experiments


@pytest.mark.parametrize("disk", ["0", "-2", "10000"])
def test_plot_experiments_refuses_a_tracked_disk_the_runs_do_not_have(disk, tmp_path, capsys):
    # --track 0 drew the last disk (index -1) under the title 'disk 0', with exit 0
    for case in plot_experiments.CASES:
        (tmp_path / case).mkdir()
        write_coupled(tmp_path / case / f"{case}.h5", title=case)
    assert plot_experiments.main(["--results", str(tmp_path), "--track", disk]) == 1
    err = capsys.readouterr().err
    assert f"no disk {disk} (the run has disks 1.." in err
    assert not list(tmp_path.glob("history_*"))
