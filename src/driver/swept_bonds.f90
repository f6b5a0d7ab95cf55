!> Bonded chains are the worst case of Gauss-Seidel sweeps: information travels about one
!> contact per sweep, so the change over a sweep, which the stopping test measures, is small
!> long before the reactions are right. An audit's clamped row of 12 bonded disks under a
!> ramped tip load, swept with `method = nlgs`: at the default tolerance (1.666e-4) every step
!> was reported converged while its tip sagged 18 mm (96 mm later), and a bond was lost, its
!> gap past the alert distance, below its strength; at 1e-6 the root broke at step 11 instead
!> of 501; at 1e-8 it broke at 501, after up to 149 428 sweeps per step. `method = block` (the
!> default) kept the tip at 7e-20 m and broke the root at the step of the closed form. A deck
!> that sweeps its bonds at a tolerance above 1e-8 is accepted with a warning at its `[solver]
!> method` line that says so.
module driver_swept_bonds
    use core_kinds, only: wp
    use core_strings, only: to_str
    use io_deck, only: deck_t
    implicit none
    private
    public :: swept_bonds_warning

    !> The tolerance from which the audit's swept row broke where the closed form says.
    real(wp), parameter :: trusted_tolerance = 1.0e-8_wp
    !> The schema's default tolerance (io_schema_dem).
    real(wp), parameter :: default_tolerance = 1.666e-4_wp

contains

    !> The warning for a deck with `[contacts] bond` records whose `[solver] method` sweeps
    !> the bonds (`nlgs` or `coarse`: the coarse correction leaves bonds out) at a tolerance
    !> above 1e-8; '' otherwise.
    function swept_bonds_warning(deck) result(message)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The warning, or ''.
        character(len=:), allocatable :: message
        character(len=:), allocatable :: method
        real(wp) :: tolerance
        message = ''
        if (.not. (deck%has('contacts', 'bond') .and. deck%has('solver', 'method'))) return
        method = deck%get_word('solver', 'method')
        if (method == 'block') return
        tolerance = default_tolerance
        if (deck%has('solver', 'tolerance')) tolerance = deck%get_real('solver', 'tolerance')
        if (tolerance <= trusted_tolerance) return
        message = 'warning: '//deck%file//':'//to_str(deck%line('solver', 'method'))//': [solver] method = '// &
                  method//' sweeps the bonds of [contacts] bond (line '//to_str(deck%line('contacts', 'bond'))// &
                  ') one contact at a time: along a bonded chain the sweeps converge slowly, and their '// &
                  'stopping test can be met far from the solution (a clamped row of 12 bonded disks: at the '// &
                  'default tolerance it sagged 18 mm in steps reported converged and lost a bond below its '// &
                  'strength, at 1e-6 its root broke at step 11 instead of 501, at 1e-8 it was right after up to '// &
                  '149 428 sweeps per step); method = block (the default) solves the intact bonds directly'
    end function swept_bonds_warning
end module driver_swept_bonds
