!> The simulation extension of a deck's kind of run, decided in one place from the sections
!> that hold keywords (a `[section]` header alone counts for nothing):
!> - [continuum] alone: a 2D continuum run, its extension that of its `[run] analysis`;
!> - [continuum], [particles] and [coupling] (region lines): a coupled continuum-disk run;
!> - [beam] and [particles]: a coupled (Arlequin) run, which needs a [coupling] section;
!> - [particles] alone: a discrete-element run;
!> - otherwise a beam (finite-element) run, its extension that of its `[run] analysis`;
!>   without [beam] keywords building it reports that the model has no element.
!>
!> `select_simulation` refuses the sections that make no kind of run ([coupling] without both
!> models, [continuum] with [beam], or with only one of [particles] and [coupling]), then
!> the keywords that the kind of run would ignore (the extension's `check_deck`), each error
!> naming file, line and keyword. Adding a kind of run adds its extension's file (see
!> driver_simulation: its bindings, its entry in src/CMakeLists.txt, its keywords in the
!> schema) and here its case in `select_simulation` and the sections that make it.
module driver_simulations
    use core_error, only: error_t, make_input_error, make_internal_error
    use io_deck, only: deck_t
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
        call check_sections(deck, error)
        if (allocated(error)) return
        if (deck%has_section('continuum') .and. deck%has_section('particles')) then
            allocate (coupled2d_simulation_t :: sim)
        else if (deck%has_section('continuum')) then
            select case (deck%get_word('run', 'analysis'))
            case ('static')
                allocate (continuum_static_t :: sim)
            case ('modal')
                allocate (continuum_modal_t :: sim)
            case ('dynamic')
                allocate (continuum_dynamic_t :: sim)
            case default
                call unknown_analysis(error)
                return
            end select
        else if (deck%has_section('particles') .and. deck%has_section('beam')) then
            allocate (coupled_simulation_t :: sim)
        else if (deck%has_section('particles')) then
            allocate (dem_simulation_t :: sim)
        else
            select case (deck%get_word('run', 'analysis'))
            case ('static')
                allocate (beam_static_t :: sim)
            case ('modal')
                allocate (beam_modal_t :: sim)
            case ('dynamic')
                allocate (beam_dynamic_t :: sim)
            case default
                call unknown_analysis(error)
                return
            end select
        end if
        call sim%check_deck(deck, error)
    contains
        ! the schema allows static, modal and dynamic: another word is a bug (a word added to
        ! the schema without its extension)
        subroutine unknown_analysis(error)
            type(error_t), allocatable, intent(out) :: error
            call make_internal_error(error, 'select_simulation', "[run] analysis = '"// &
                                     deck%get_word('run', 'analysis')//"' has no simulation extension")
        end subroutine unknown_analysis
    end subroutine select_simulation

    !> Error when the sections of a deck make no kind of run.
    subroutine check_sections(deck, error)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        logical :: particles, beam, coupling
        integer :: k
        particles = deck%has_section('particles')
        beam = deck%has_section('beam')
        coupling = deck%has_section('coupling')
        if (deck%has_section('continuum')) then
            if (beam .or. (particles .neqv. coupling)) then
                call make_input_error(error, deck%file, deck%line('run', 'analysis'), '', &
                                      'a [continuum] deck cannot have [beam], and couples [particles] only with '// &
                                      'a [coupling] section (region lines): run the continuum alone, or give both '// &
                                      '[particles] and [coupling]')
                return
            end if
        else if (particles .and. beam .and. .not. coupling) then
            call make_input_error(error, deck%file, deck%line('run', 'analysis'), '', &
                                  'this deck has both [beam] and [particles]: coupled runs need a '// &
                                  '[coupling] section (at least overlap = s_fe s_particle and thickness; '// &
                                  'doc/input.md), or run the beam and the particles apart')
            return
        else if (coupling .and. .not. (particles .and. beam)) then
            do k = 1, size(deck%entries)
                if (deck%entries(k)%section == 'coupling') exit
            end do
            call make_input_error(error, deck%file, deck%entries(k)%line, &
                                  deck%entries(k)%keyword, '[coupling] glues particles to a beam, and this '// &
                                  'deck has no '//trim(merge('[particles]', '[beam]     ',.not. particles))// &
                                  ': remove [coupling] or add the missing model')
            return
        end if
    end subroutine check_sections
end module driver_simulations
