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
    public :: break_none, break_tension, break_shear, break_moment, break_shear_moment
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
        !> Mode (break_tension, break_shear, break_moment, break_shear_moment).
        integer, allocatable :: mode(:)
    contains
        !> Append one rupture.
        procedure :: add => rupture_log_add
    end type rupture_log_t

contains

    !> Name of a rupture mode ('tension', 'shear', 'moment', 'shear+moment', or 'none').
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
        case default
            name = 'none'
        end select
    end function break_mode_name

    !> Append one rupture (the arrays grow by half when full).
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
        integer :: cap
        if (.not. allocated(self%i1)) then
            allocate (self%i1(16), self%i2(16), self%step(16), self%time(16), self%mode(16))
        else if (self%n == size(self%i1)) then
            cap = self%n + self%n/2 + 1
            call grow_i(self%i1, cap)
            call grow_i(self%i2, cap)
            call grow_i(self%mode, cap)
            call grow_i8(self%step, cap)
            call grow_r(self%time, cap)
        end if
        self%n = self%n + 1
        self%i1(self%n) = i1
        self%i2(self%n) = i2
        self%step(self%n) = step
        self%time(self%n) = time
        self%mode(self%n) = mode
    contains
        pure subroutine grow_i(a, m)
            integer, allocatable, intent(inout) :: a(:)
            integer, intent(in) :: m
            integer, allocatable :: t(:)
            allocate (t(m))
            t(1:size(a)) = a
            call move_alloc(t, a)
        end subroutine grow_i

        pure subroutine grow_i8(a, m)
            integer(i8), allocatable, intent(inout) :: a(:)
            integer, intent(in) :: m
            integer(i8), allocatable :: t(:)
            allocate (t(m))
            t(1:size(a)) = a
            call move_alloc(t, a)
        end subroutine grow_i8

        pure subroutine grow_r(a, m)
            real(wp), allocatable, intent(inout) :: a(:)
            integer, intent(in) :: m
            real(wp), allocatable :: t(:)
            allocate (t(m))
            t(1:size(a)) = a
            call move_alloc(t, a)
        end subroutine grow_r
    end subroutine rupture_log_add
end module dem_bonds
