!> Bond ruptures: the modes in which an intact bond breaks and the log of the ruptures of a
!> run (doc/theory.md, "Bonded contacts").
!>
!> An intact bond holds (r_n + r_cohe, r_t, M) in the cone {|r_t| <= mu_b (r_n + r_cohe),
!> |M| <= e_b (r_n + r_cohe)}. It breaks for good, at a converged step, when the solution
!> reaches the apex (tension: full tension and opening), the sliding bound (shear), the
!> rolling bound (moment) or both bounds at once (shear and moment).
module dem_bonds
    use core_kinds, only: wp, i8
    implicit none
    private
    public :: break_none, break_tension, break_shear, break_moment, break_shear_moment, break_lost
    public :: break_mode_name, rupture_log_t

    !> Not broken (this step).
    integer, parameter :: break_none = 0
    !> Broken in tension: full tension and the contact opens.
    integer, parameter :: break_tension = 1
    !> Broken in shear: the tangential bound mu_b (r_n + r_cohe) reached.
    integer, parameter :: break_shear = 2
    !> Broken in bending: the moment bound e_b (r_n + r_cohe) reached.
    integer, parameter :: break_moment = 3
    !> Broken with both the shear and the moment bounds reached.
    integer, parameter :: break_shear_moment = 4
    !> The bond was lost: the detection no longer found the pair (its gap beyond the alert distance; the
    !> bond held the velocity, and the positions drifted apart: dem_contacts,
    !> contacts_lost_bonds). Not a rupture of the law: a limit of the rigid bond's scheme.
    integer, parameter :: break_lost = 5

    !> Ruptures of a run, in the order they happen.
    type :: rupture_log_t
        !> Number of ruptures.
        integer :: n = 0
        !> Bodies of each broken bond: first (disk, or -wall) and second (disk).
        integer, allocatable :: i1(:), i2(:)
        !> Step at the end of which the bond broke (1 = first step).
        integer(i8), allocatable :: step(:)
        !> Time at the end of that step [s].
        real(wp), allocatable :: time(:)
        !> Mode (break_tension, break_shear, break_moment, break_shear_moment, break_lost).
        integer, allocatable :: mode(:)
    contains
        !> Append one rupture.
        procedure :: add => rupture_log_add
    end type rupture_log_t

contains

    !> Name of a rupture mode ('tension', 'shear', 'moment', 'shear+moment', 'lost', or 'none').
    pure function break_mode_name(mode) result(name)
        !> One of the break_* values.
        integer, intent(in) :: mode
        character(len=:), allocatable :: name
        select case (mode)
        case (break_tension)
            name = 'tension'
        case (break_shear)
            name = 'shear'
        case (break_moment)
            name = 'moment'
        case (break_shear_moment)
            name = 'shear+moment'
        case (break_lost)
            name = 'lost'
        case default
            name = 'none'
        end select
    end function break_mode_name

    !> Append one rupture (ruptures are rare events: the arrays grow by one).
    pure subroutine rupture_log_add(self, i1, i2, step, time, mode)
        !> The log.
        class(rupture_log_t), intent(inout) :: self
        !> Bodies of the bond.
        integer, intent(in) :: i1, i2
        !> Step of the rupture.
        integer(i8), intent(in) :: step
        !> Time of the rupture [s].
        real(wp), intent(in) :: time
        !> Mode of the rupture.
        integer, intent(in) :: mode
        if (.not. allocated(self%i1)) allocate (self%i1(0), self%i2(0), self%step(0), self%time(0), self%mode(0))
        self%i1 = [self%i1, i1]
        self%i2 = [self%i2, i2]
        self%step = [self%step, step]
        self%time = [self%time, time]
        self%mode = [self%mode, mode]
        self%n = self%n + 1
    end subroutine rupture_log_add
end module dem_bonds
