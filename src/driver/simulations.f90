!> The simulation extension of a deck's kind of run (driver_run_kind): [beam] alone is a
!> finite-element run, [particles] alone a discrete-element run, both a coupled (Arlequin)
!> run, [continuum] alone a 2D continuum run, [continuum] with [particles] and [coupling] a
!> coupled continuum-disk run. A beam or continuum run's extension is that of its `[run]
!> analysis`.
module driver_simulations
    use core_error, only: error_t
    use io_deck, only: deck_t
    use driver_run_kind, only: run_kind_of, check_run_kind, run_beam, run_particles, run_coupled, &
                               run_continuum, run_coupled2d
    use driver_simulation, only: simulation_t
    use driver_simulation_beam_static, only: beam_static_t
    use driver_simulation_beam_modal, only: beam_modal_t
    use driver_simulation_beam_dynamic, only: beam_dynamic_t
    use driver_simulation_dem, only: dem_simulation_t
    use driver_simulation_coupled, only: coupled_simulation_t
    use driver_simulation_continuum_static, only: continuum_static_t
    use driver_simulation_continuum_modal, only: continuum_modal_t
    use driver_simulation_continuum_dynamic, only: continuum_dynamic_t
    use driver_simulation_coupled2d, only: coupled2d_simulation_t
    implicit none
    private
    public :: select_simulation

contains

    !> The simulation extension for the deck (not yet initialised).
    subroutine select_simulation(deck, sim, error)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The simulation of the deck's kind.
        class(simulation_t), allocatable, intent(out) :: sim
        !> Set when the sections do not make a kind of run, or when the deck sets keywords
        !> that its kind of run does not use.
        type(error_t), allocatable, intent(out) :: error
        call check_run_kind(deck, error)
        if (allocated(error)) return
        select case (run_kind_of(deck))
        case (run_continuum)
            select case (deck%get_word('run', 'analysis'))
            case ('static')
                allocate (continuum_static_t :: sim)
            case ('modal')
                allocate (continuum_modal_t :: sim)
            case default
                ! 'dynamic' (the schema allows these three words)
                allocate (continuum_dynamic_t :: sim)
            end select
        case (run_coupled2d)
            allocate (coupled2d_simulation_t :: sim)
        case (run_coupled)
            allocate (coupled_simulation_t :: sim)
        case (run_particles)
            allocate (dem_simulation_t :: sim)
        case (run_beam)
            select case (deck%get_word('run', 'analysis'))
            case ('static')
                allocate (beam_static_t :: sim)
            case ('modal')
                allocate (beam_modal_t :: sim)
            case default
                ! 'dynamic' (the schema allows these three words)
                allocate (beam_dynamic_t :: sim)
            end select
        end select
    end subroutine select_simulation
end module driver_simulations
