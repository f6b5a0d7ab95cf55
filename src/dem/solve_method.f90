!> The global strategy of a step's contact solve (`[solver] method`; doc/theory.md
!> sections 4.1 and 7.10): an abstract type whose `solve` takes the settings, the contacts
!> and the free velocities and gives the reactions and the end-of-step velocities, and its
!> plain kind, the NLGS sweeps over every contact (`method = nlgs`, and `method = coarse`,
!> the sweeps with the coarse correction that the settings hold). The intact bonds solved
!> directly as one block (`method = block`) extend it in dem_bonded_block
!> (bonded_block_method_t). The strategy is state: the block keeps its factor from step to
!> step, so the system holds it (dem_moreau_jean, `dem_system_t%method`), next to the
!> settings.
module dem_solve_method
    use core_kinds, only: wp
    use core_error, only: error_t
    use core_state, only: state_sink_t, state_source_t
    use dem_contacts, only: contact_set_t
    use dem_nlgs, only: nlgs_config_t, nlgs_stats_t, nlgs_bilateral_t, nlgs_solve
    implicit none
    private
    public :: solve_method_t, sweeps_method_t

    !> A global strategy of the contact solve.
    type, abstract :: solve_method_t
    contains
        !> Solve the contact problem of one step (arguments as nlgs_solve).
        procedure(method_solve), deferred :: solve
        !> Name, with the settings (the value of `[solver] method`).
        procedure(method_name), deferred :: name
        !> Put the state kept between steps into a checkpoint.
        procedure(method_save_state), deferred :: save_state
        !> Take it back from a checkpoint (the strategy built from the deck).
        procedure(method_load_state), deferred :: load_state
    end type solve_method_t

    abstract interface
        !> Name of a strategy with the settings.
        pure function method_name(self, config) result(name)
            import :: solve_method_t, nlgs_config_t
            !> The strategy.
            class(solve_method_t), intent(in) :: self
            !> Settings.
            type(nlgs_config_t), intent(in) :: config
            character(len=:), allocatable :: name
        end function method_name

        !> Solve the contact problem of one step: on entry vel holds the free velocities and
        !> cs%r the warm start, on exit the end-of-step velocities and the reactions.
        subroutine method_solve(self, config, cs, im, vel, stats, bilateral)
            import :: solve_method_t, nlgs_config_t, contact_set_t, wp, nlgs_stats_t, nlgs_bilateral_t
            !> The strategy (and its state kept between steps).
            class(solve_method_t), intent(inout) :: self
            !> Settings.
            type(nlgs_config_t), intent(in) :: config
            !> Contacts (frames, laws and activity set).
            type(contact_set_t), intent(inout) :: cs
            !> Inverse mass per DOF (3, n_disks).
            real(wp), intent(in) :: im(:, :)
            !> Velocities (3, n_disks).
            real(wp), intent(inout) :: vel(:, :)
            !> Statistics.
            type(nlgs_stats_t), intent(out) :: stats
            !> Bilateral constraints kept satisfied (default: none).
            class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        end subroutine method_solve

        !> Put the state kept between steps (nothing for a strategy without one).
        subroutine method_save_state(self, sink, error)
            import :: solve_method_t, state_sink_t, error_t
            !> The strategy.
            class(solve_method_t), intent(in) :: self
            !> Where the state goes.
            class(state_sink_t), intent(inout) :: sink
            !> Set on a write failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine method_save_state

        !> Take back the state put by `save_state`, checking it against the system's bodies.
        subroutine method_load_state(self, source, n_disks, n_walls, error)
            import :: solve_method_t, state_source_t, error_t
            !> The strategy (built from the deck).
            class(solve_method_t), intent(inout) :: self
            !> Where the state comes from.
            class(state_source_t), intent(in) :: source
            !> Numbers of disks and walls of the system.
            integer, intent(in) :: n_disks, n_walls
            !> Set on a read failure, a damaged value, or a state of another strategy.
            type(error_t), allocatable, intent(out) :: error
        end subroutine method_load_state
    end interface

    !> NLGS sweeps over every contact (`method = nlgs`; `coarse` with the settings'
    !> correction). No state.
    type, extends(solve_method_t) :: sweeps_method_t
    contains
        !> dem_nlgs's solve.
        procedure :: solve => sweeps_solve
        !> 'nlgs', or 'coarse' with the settings' correction.
        procedure :: name => sweeps_name
        !> Nothing to put.
        procedure :: save_state => sweeps_save_state
        !> Nothing to take back: a stored state is another strategy's.
        procedure :: load_state => sweeps_load_state
    end type sweeps_method_t

contains

    !> 'nlgs', or 'coarse' when the settings hold a correction (the only one is dem_coarse's).
    pure function sweeps_name(self, config) result(name)
        !> The strategy.
        class(sweeps_method_t), intent(in) :: self
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        character(len=:), allocatable :: name
        if (allocated(config%correction)) then
            name = 'coarse'
        else
            name = 'nlgs'
        end if
    end function sweeps_name

    !> The NLGS sweeps (nlgs_solve).
    subroutine sweeps_solve(self, config, cs, im, vel, stats, bilateral)
        !> The strategy (no state).
        class(sweeps_method_t), intent(inout) :: self
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        !> Contacts (frames, laws and activity set).
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        !> Statistics.
        type(nlgs_stats_t), intent(out) :: stats
        !> Bilateral constraints kept satisfied (default: none).
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        call nlgs_solve(config, cs, im, vel, stats, bilateral)
    end subroutine sweeps_solve

    !> Nothing to put: the sweeps keep no state between steps.
    subroutine sweeps_save_state(self, sink, error)
        !> The strategy.
        class(sweeps_method_t), intent(in) :: self
        !> Where the state goes.
        class(state_sink_t), intent(inout) :: sink
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
    end subroutine sweeps_save_state

    !> Nothing to take back; a stored state (that of the bonded block) is an error: the deck,
    !> whose hash the checkpoint matches, chose the strategy.
    subroutine sweeps_load_state(self, source, n_disks, n_walls, error)
        !> The strategy.
        class(sweeps_method_t), intent(inout) :: self
        !> Where the state comes from.
        class(state_source_t), intent(in) :: source
        !> Numbers of disks and walls of the system.
        integer, intent(in) :: n_disks, n_walls
        !> Set when a state is stored.
        type(error_t), allocatable, intent(out) :: error
        if (.not. source%is_empty()) call source%damaged('the deck solves no bonded block ([solver] method)', error)
    end subroutine sweeps_load_state
end module dem_solve_method
