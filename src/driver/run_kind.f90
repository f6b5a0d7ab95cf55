!> Checks of a deck against the keywords its kind of run uses, shared by the kinds: each
!> simulation's `check_deck` (driver_simulation) calls those that apply to it (a beam or a
!> continuum run takes no particle settings, a particle run no beam settings, a continuum run
!> no [initial]). Each error names file, line and keyword. Which sections make which kind of
!> run is decided in one place, driver_simulations.
module driver_run_kind
    use core_error, only: error_t, make_input_error
    use io_deck, only: deck_t
    implicit none
    private
    public :: check_particle_keywords_unused, check_beam_keywords_unused, check_initial_unused

contains

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
