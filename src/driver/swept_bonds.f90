!> Bonded chains are the worst case of Gauss-Seidel sweeps: information travels about one
!> contact per sweep, so the change over a sweep, which the stopping test measures, is small
!> long before the reactions are right. An audit's clamped row of 12 bonded disks under a
!> ramped tip load, swept with `method = nlgs` at the default tolerance, reported every step
!> converged while its tip sagged 18 mm (96 mm later), and a bond was lost, its gap past the
!> alert distance, below its strength; `method = block` (the default) kept the tip at 7e-20 m
!> and broke the root at the step of the closed form. A deck that sweeps its bonds is
!> accepted with a warning at its `[solver] method` line that says so.
module driver_swept_bonds
    use core_strings, only: to_str
    use io_deck, only: deck_t
    implicit none
    private
    public :: swept_bonds_warning

contains

    !> The warning for a deck with `[contacts] bond` records whose `[solver] method` sweeps
    !> the bonds (`nlgs` or `coarse`: the coarse correction leaves bonds out); '' otherwise.
    function swept_bonds_warning(deck) result(message)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The warning, or ''.
        character(len=:), allocatable :: message
        character(len=:), allocatable :: method
        message = ''
        if (.not. (deck%has('contacts', 'bond') .and. deck%has('solver', 'method'))) return
        method = deck%get_word('solver', 'method')
        if (method == 'block') return
        message = 'warning: '//deck%file//':'//to_str(deck%line('solver', 'method'))//': [solver] method = '// &
                  method//' sweeps the bonds of [contacts] bond (line '//to_str(deck%line('contacts', 'bond'))// &
                  ') one contact at a time: along a bonded chain the sweeps converge slowly, and their '// &
                  'stopping test can be met far from the solution (a clamped row of 12 bonded disks at the '// &
                  'default tolerance sagged 18 mm in steps reported converged, and a bond was lost below its '// &
                  'strength); method = block (the default) solves the intact bonds directly'
    end function swept_bonds_warning
end module driver_swept_bonds
