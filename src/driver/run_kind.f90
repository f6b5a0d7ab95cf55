!> The kind of run a deck asks for, decided in one place from the sections that hold
!> keywords (a `[section]` header alone counts for nothing):
!> - [continuum] alone: a 2D continuum run;
!> - [continuum], [particles] and [coupling] (region lines): a coupled continuum-disk run;
!> - [beam] and [particles]: a coupled (Arlequin) run, which needs a [coupling] section;
!> - [particles] alone: a discrete-element run;
!> - otherwise a beam (finite-element) run; without [beam] keywords building it reports that
!>   the model has no element.
!>
!> `run_kind_of` gives the kind; `check_run_kind` refuses the sections that make no kind of
!> run ([coupling] without both models, [continuum] with [beam], or with only one of
!> [particles] and [coupling]) and the keywords that
!> the kind of run would ignore (particle settings in a deck without particles, beam
!> settings and [initial] in a deck without a beam), each error naming file, line and keyword.
!> `run_kind_warnings` lists the settings a coupled run accepts but does not use (the coarse
!> correction and the hydrostatic cold start do not act on the coupling rows: documented
!> fallbacks, so a warning rather than an error).
module driver_run_kind
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, to_str
    use io_deck, only: deck_t
    implicit none
    private
    public :: run_beam, run_particles, run_coupled, run_continuum, run_coupled2d
    public :: run_kind_of, check_run_kind, run_kind_warnings

    !> Kind of run: beam finite elements ([beam] alone).
    integer, parameter :: run_beam = 1
    !> Kind of run: discrete elements ([particles] alone).
    integer, parameter :: run_particles = 2
    !> Kind of run: beam and particles coupled by Arlequin ([beam], [particles], [coupling]).
    integer, parameter :: run_coupled = 3
    !> Kind of run: 2D elastic continuum ([continuum] alone).
    integer, parameter :: run_continuum = 4
    !> Kind of run: 2D continuum and particles coupled by Arlequin ([continuum], [particles],
    !> [coupling] with region lines).
    integer, parameter :: run_coupled2d = 5

contains

    !> Kind of run of a deck, from its sections (run_beam, run_particles, run_coupled,
    !> run_continuum or run_coupled2d); `check_run_kind` says whether the sections go together.
    pure integer function run_kind_of(deck) result(kind)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        if (deck%has_section('continuum') .and. deck%has_section('particles')) then
            kind = run_coupled2d
        else if (deck%has_section('continuum')) then
            kind = run_continuum
        else if (deck%has_section('particles') .and. deck%has_section('beam')) then
            kind = run_coupled
        else if (deck%has_section('particles')) then
            kind = run_particles
        else
            kind = run_beam
        end if
    end function run_kind_of

    !> Error when the sections of a deck make no kind of run, or when it sets keywords that
    !> its kind of run does not use (they would have no effect).
    subroutine check_run_kind(deck, error)
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
        select case (run_kind_of(deck))
        case (run_beam)
            call check_particle_keywords_unused(deck, error)
        case (run_continuum)
            call check_particle_keywords_unused(deck, error)
            if (allocated(error)) return
            call check_initial_unused(deck, error)
        case (run_particles)
            call check_beam_keywords_unused(deck, error)
        end select
    end subroutine check_run_kind

    !> Warnings for the solver settings that a coupled run accepts and does not use, as
    !> 'warning: file:line: ...': `method = coarse` (a coupled run sweeps as with `nlgs`) and
    !> `cold_start = hydrostatic` (its estimate leaves out the coupling rows).
    function run_kind_warnings(deck) result(warnings)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        type(string_t), allocatable :: warnings(:)
        allocate (warnings(0))
        select case (run_kind_of(deck))
        case (run_coupled, run_coupled2d)
            if (set_to('method', 'coarse')) &
                warnings = [warnings, string_t('warning: '//deck%file//':'//to_str(deck%line('solver', 'method'))// &
                                               ': [solver] method = coarse has no effect in a coupled run: '// &
                                               'the coarse correction does not act on the coupling rows, and the run '// &
                                               'sweeps as with method = nlgs')]
            if (set_to('cold_start', 'hydrostatic')) &
                warnings = [warnings, string_t('warning: '//deck%file//':'//to_str(deck%line('solver', 'cold_start'))// &
                                               ': [solver] cold_start = hydrostatic has no effect in a coupled run: '// &
                                               'the hydrostatic estimate leaves out the coupling rows, and a step without '// &
                                               'reactions starts from zero')]
        end select
    contains
        ! whether the deck itself sets [solver] keyword to value
        logical function set_to(keyword, value)
            character(len=*), intent(in) :: keyword, value
            set_to = .false.
            if (deck%has('solver', keyword)) set_to = deck%get_word('solver', keyword) == value
        end function set_to
    end function run_kind_warnings

    !> Error for a deck without [particles] that sets particle-only keywords ([walls],
    !> [contacts], [solver], [time] theta and contact_scheme, [output] contacts): they would
    !> have no effect.
    subroutine check_particle_keywords_unused(deck, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Error naming the first such keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                select case (e%section)
                case ('walls', 'contacts', 'solver')
                case ('time')
                    if (e%keyword /= 'theta' .and. e%keyword /= 'contact_scheme') cycle
                case ('output')
                    if (e%keyword /= 'contacts') cycle
                case default
                    cycle
                end select
                call make_input_error(error, deck%file, e%line, e%keyword, '['//e%section// &
                                      '] '//e%keyword//' applies to particles, and this deck has no [particles]'// &
                                      ': remove it or add particles')
                return
            end associate
        end do
    end subroutine check_particle_keywords_unused

    !> Error for a deck of particles without [beam] that sets beam-only keywords ([time]
    !> scheme, beta, gamma, [modal], [initial]): they would have no effect.
    subroutine check_beam_keywords_unused(deck, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Error naming the first such keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                select case (e%section)
                case ('modal')
                case ('initial')
                    call make_input_error(error, deck%file, e%line, e%keyword, '[initial] '// &
                                          'sets beam nodes, and this deck has no [beam]; the initial velocities '// &
                                          'of disks are [particles] initial_velocity records')
                    return
                case ('time')
                    if (e%keyword /= 'scheme' .and. e%keyword /= 'beta' .and. &
                        e%keyword /= 'gamma') cycle
                case default
                    cycle
                end select
                call make_input_error(error, deck%file, e%line, e%keyword, '['//e%section// &
                                      '] '//e%keyword//' applies to the beam, and this deck has no [beam]: '// &
                                      'remove it (particles use [time] theta)')
                return
            end associate
        end do
    end subroutine check_beam_keywords_unused

    !> Error for a continuum deck with [initial] (which sets beam DOFs).
    subroutine check_initial_unused(deck, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Error naming the first [initial] keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        do k = 1, size(deck%entries)
            if (deck%entries(k)%section == 'initial') then
                call make_input_error(error, deck%file, deck%entries(k)%line, deck%entries(k)%keyword, &
                                      '[initial] sets beam dofs; the continuum takes [continuum] initial_velocity')
                return
            end if
        end do
    end subroutine check_initial_unused
end module driver_run_kind
