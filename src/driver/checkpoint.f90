!> Checkpoints of a time loop and restart from them (doc/output.md, "Checkpoints and restart").
!>
!> A checkpoint is an HDF5 file holding everything a time loop needs to go on as if it had
!> never stopped: the mutable state of the models (Newmark state of a beam or a 2D continuum;
!> Moreau-Jean state of the disks and walls, the contact list with its reactions and statuses
!> for the warm start, bond states and the rupture log; multipliers and constraint state of a
!> coupling, with a beam or a continuum),
!> the counters of the results writers and the record count of every dataset of the results
!> file, the loop's own counters (with the wall time of the analysis up to the checkpoint and
!> its number of runs, which a restart continues), and a header: code version, a hash of the deck's text, the
!> kind of run, the step. What the deck builds (meshes, matrices, materials, functions) is
!> built again from the deck at restart and not stored. There is no random state in a time
!> loop: the random deposit is generated from the deck's seed when the model is built.
!>
!> Every value read back is checked before the run uses it: reals finite, counts, step
!> numbers, body numbers and codes in their ranges, array sizes those of the deck's model;
!> anything else is refused as 'the checkpoint is damaged', naming the value, before the
!> results file is written to.
!>
!> The file is written as '<path>.tmp' and renamed to `path` (atomic on POSIX): a kill
!> during the write leaves the previous checkpoint intact. Before a run replaces the
!> checkpoint it found (an earlier run's, or the one it restarts from) for the first time,
!> that one gets the second name '<path>.prev' (a hard link): a run that fails puts it back
!> (`checkpoint_run_t%revert`), a run that ends or is stopped by a signal deletes it
!> (`settle`).
!>
!> This module gathers the public API of the checkpoint modules: the file and its header
!> (driver_checkpoint_file), the loop's counters and the end of a step (driver_checkpoint_loop),
!> the state of a time integrator (driver_checkpoint_fem), of the particles
!> (driver_checkpoint_dem) and of a coupled system (driver_checkpoint_coupling), the results
!> writers (driver_checkpoint_results) and the checked reading of values
!> (driver_checkpoint_values).
module driver_checkpoint
    use driver_checkpoint_values, only: read_finite_attribute
    use driver_checkpoint_loop, only: loop_state_t, checkpoint_schedule_t, step_end_t, end_of_step, save_loop, &
                                      load_loop, rest_of_last_step
    use driver_checkpoint_file, only: checkpoint_name, deck_hash, checkpoint_run_t, checkpoint_create, &
                                      checkpoint_commit, checkpoint_open, checkpoint_discard, checkpoint_owner
    use driver_checkpoint_fem, only: save_integrator, load_integrator
    use driver_checkpoint_dem, only: save_dem, load_dem
    use driver_checkpoint_coupling, only: save_coupled, load_coupled
    use driver_checkpoint_results, only: save_results, load_results, save_dem_writer, load_dem_writer, &
                                         save_coupled_writer, load_coupled_writer, checkpoint_results_mark
    implicit none
    private
    public :: checkpoint_name, deck_hash, loop_state_t, checkpoint_schedule_t
    public :: checkpoint_create, checkpoint_commit, checkpoint_open, checkpoint_discard
    public :: save_integrator, load_integrator, save_dem, load_dem, save_coupled, load_coupled
    public :: save_results, load_results, save_dem_writer, load_dem_writer
    public :: save_coupled_writer, load_coupled_writer, save_loop, load_loop, checkpoint_results_mark
    public :: checkpoint_run_t, step_end_t, end_of_step, rest_of_last_step, read_finite_attribute, checkpoint_owner
end module driver_checkpoint
