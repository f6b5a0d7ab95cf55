!> One kind of run (beam, particles, coupled, continuum) as an extension of one abstract type.
!>
!> `driver_run` reads the deck, lets `driver_simulations` pick the extension from the deck's
!> sections (which then refuses, through `check_deck`, the keywords the kind does not use),
!> then calls, in order: `init` (build the configuration and the model from the
!> deck; everything that can fail because of the input fails here, before the results folder
!> is touched), `deck_warnings` (settings accepted without effect), `describe` (the line of a
!> `--check` run), and `run` (static solve, modes or time steps, writing every output into the
!> open results file). A run with a time loop (`has_time_loop`) can be extended (`--end`) and
!> restarted; its checkpoints (driver_checkpoint) name its kind of run with `checkpoint_kind`,
!> which a restart checks. Before `init`, `size_estimate` adds the parts of the model the deck
!> asks for to the memory estimate (driver_model_size). Adding a kind of model adds an
!> extension in its own file (every deferred binding above; a coupled kind may combine the
!> bindings of the kinds it couples), listed in src/CMakeLists.txt, its keywords in the schema
!> (io), and its case in `driver_simulations`, which picks it from the deck's sections. A kind
!> that writes a results group of its own also adds its XDMF part type (driver_xdmf_part) in
!> its own file and one line in `registered_parts` of driver_results_xdmf.
module driver_simulation
    use, intrinsic :: iso_fortran_env, only: output_unit
    use core_error, only: error_t
    use core_signals, only: broken_pipe
    use core_strings, only: string_t
    use io_deck, only: deck_t
    use driver_results, only: results_writer_t
    use driver_config, only: run_config_t
    use driver_checkpoint, only: checkpoint_run_t
    use driver_model_size, only: size_estimate_t
    implicit none
    private
    public :: simulation_t, report_iface, report_to_stdout

    abstract interface
        !> Receives one line of progress or summary text.
        subroutine report_iface(line)
            !> The line.
            character(len=*), intent(in) :: line
        end subroutine report_iface
    end interface

    !> A run of one kind of model.
    type, abstract :: simulation_t
        !> Run settings (analysis, time step, end time, outputs, checkpoints), from `init`.
        type(run_config_t) :: settings
    contains
        !> Build the configuration and the model from the deck; check everything that depends
        !> on the input.
        procedure(simulation_init), deferred :: init
        !> What a `--check` run says about the valid deck.
        procedure(simulation_describe), deferred :: describe
        !> Run the analysis and write its results.
        procedure(simulation_run), deferred :: run
        !> Kind of run written in and checked against a checkpoint ('beam', 'particles',
        !> 'coupled', 'continuum', 'coupled2d'); '' for a run without checkpoints (static and
        !> modal analyses).
        procedure(simulation_checkpoint_kind), deferred :: checkpoint_kind
        !> Whether the run integrates in time (steps, checkpoints, `--end` and `--restart`),
        !> rather than a static solve or modes.
        procedure(simulation_has_time_loop), deferred :: has_time_loop
        !> Error when the deck sets keywords that this kind of run does not use (they would
        !> have no effect); called before `init`.
        procedure(simulation_check_deck), deferred :: check_deck
        !> Warnings for settings that this kind of run accepts and does not use.
        procedure(simulation_deck_warnings), deferred :: deck_warnings
        !> Add the parts of the model the deck asks for to the estimate of its memory (from
        !> the deck alone: called after `check_deck`, before `init` allocates anything).
        procedure(simulation_size_estimate), deferred :: size_estimate
        !> Text that stands for the files besides the deck the model was read from (the hash of
        !> a Gmsh mesh); hashed into checkpoints with the deck, so that a restart refuses a
        !> changed mesh. Default: none.
        procedure :: inputs_text => simulation_inputs_text
    end type simulation_t

    abstract interface
        !> Build the model from the deck (errors name file, line and keyword).
        subroutine simulation_init(self, deck, report, error)
            import :: simulation_t, deck_t, error_t, report_iface
            !> The simulation.
            class(simulation_t), intent(inout) :: self
            !> The validated deck.
            type(deck_t), intent(in) :: deck
            !> Where warnings go.
            procedure(report_iface) :: report
            !> Set on any input error.
            type(error_t), allocatable, intent(out) :: error
        end subroutine simulation_init

        !> Summary of the valid deck, e.g. 'dynamic analysis, 40 disks, 2 walls'.
        function simulation_describe(self) result(text)
            import :: simulation_t
            !> The simulation (after `init`).
            class(simulation_t), intent(in) :: self
            !> Text after 'deck is valid ('.
            character(len=:), allocatable :: text
        end function simulation_describe

        !> Run the analysis; results into `out` (open).
        subroutine simulation_run(self, out, quiet, report, ck, error)
            import :: simulation_t, results_writer_t, error_t, report_iface, checkpoint_run_t
            !> The simulation (after `init`).
            class(simulation_t), intent(inout) :: self
            !> The results file.
            type(results_writer_t), intent(inout) :: out
            !> No progress lines.
            logical, intent(in) :: quiet
            !> Where progress and summary lines go.
            procedure(report_iface) :: report
            !> Checkpoints of a time loop (and the one to restart from).
            type(checkpoint_run_t), intent(inout) :: ck
            !> Set on a run or write failure (without the deck file name).
            type(error_t), allocatable, intent(out) :: error
        end subroutine simulation_run

        !> Kind of run of the checkpoints of this simulation ('': it writes none).
        function simulation_checkpoint_kind(self) result(kind)
            import :: simulation_t
            !> The simulation (after `init`).
            class(simulation_t), intent(in) :: self
            !> 'beam', 'particles', 'coupled', 'continuum', 'coupled2d' or ''.
            character(len=:), allocatable :: kind
        end function simulation_checkpoint_kind

        !> Whether the simulation steps in time.
        pure logical function simulation_has_time_loop(self)
            import :: simulation_t
            !> The simulation.
            class(simulation_t), intent(in) :: self
        end function simulation_has_time_loop

        !> Error for keywords of the deck that the kind of run would ignore.
        subroutine simulation_check_deck(self, deck, error)
            import :: simulation_t, deck_t, error_t
            !> The simulation (not yet initialised).
            class(simulation_t), intent(in) :: self
            !> The validated deck.
            type(deck_t), intent(in) :: deck
            !> Error naming file, line and keyword, if any.
            type(error_t), allocatable, intent(out) :: error
        end subroutine simulation_check_deck

        !> Warnings ('warning: file:line: ...') for settings without effect in this kind of run.
        function simulation_deck_warnings(self, deck) result(warnings)
            import :: simulation_t, deck_t, string_t
            !> The simulation.
            class(simulation_t), intent(in) :: self
            !> The validated deck.
            type(deck_t), intent(in) :: deck
            !> The warnings (none: size 0).
            type(string_t), allocatable :: warnings(:)
        end function simulation_deck_warnings

        !> Counts of the model's parts (disks, nodes, elements) as the deck asks for them.
        subroutine simulation_size_estimate(self, deck, estimate, error)
            import :: simulation_t, deck_t, size_estimate_t, error_t
            !> The simulation (not yet initialised).
            class(simulation_t), intent(in) :: self
            !> The validated deck.
            type(deck_t), intent(in) :: deck
            !> The estimate, this kind's parts added.
            type(size_estimate_t), intent(inout) :: estimate
            !> Set when a part is larger than its kind can number (naming file, line and
            !> keyword).
            type(error_t), allocatable, intent(out) :: error
        end subroutine simulation_size_estimate
    end interface

contains

    !> The report of the command line program (a `report_iface`): the line on standard output,
    !> flushed, so that a batch log follows the run. Once standard output is a pipe whose reader
    !> has gone (SIGPIPE caught, core_signals), nothing more is printed: the run goes on.
    subroutine report_to_stdout(line)
        !> The line.
        character(len=*), intent(in) :: line
        if (broken_pipe()) return
        write (output_unit, '(a)') line
        flush (output_unit)
    end subroutine report_to_stdout
    !> See `simulation_t%inputs_text`: no file besides the deck.
    function simulation_inputs_text(self) result(text)
        !> The simulation.
        class(simulation_t), intent(in) :: self
        !> Their text ('').
        character(len=:), allocatable :: text
        text = ''
    end function simulation_inputs_text
end module driver_simulation
