!> Rigid disks in the plane (the bodies of the discrete domain), stored as structure of arrays.
!>
!> Three DOFs per disk: 1 = x, 2 = y, 3 = rotation (counter-clockwise). Mass and inertia are
!> per unit thickness: m = rho pi R^2, I = m R^2 / 2. Each DOF is free unless a condition fixes it
!> or imposes its velocity (value times a time function). Loads (forces, torques) are
!> value times a time function; gravity acts on every disk.
!> Time functions are referenced by index into `particles_t%functions` (0 = constant 1).
module dem_particles
    use core_kinds, only: wp, i8
    use core_constants, only: pi
    use core_error, only: error_t, make_error, make_internal_error
    use core_timefunc, only: time_function_slot_t
    implicit none
    private
    public :: particles_t, dof_condition_t, particle_load_t
    public :: dof_x, dof_y, dof_rot, dof_fixed, dof_imposed
    public :: particles_add_disks, particles_fix, particles_impose_velocity, particles_add_load
    public :: particles_inverse_mass, particles_constrained_velocity, particles_forces
    public :: particles_kinetic_energy, particles_potential_energy, particles_momentum
    public :: particles_time_function, particles_bytes

    !> DOF index of the x translation.
    integer, parameter :: dof_x = 1
    !> DOF index of the y translation.
    integer, parameter :: dof_y = 2
    !> DOF index of the rotation.
    integer, parameter :: dof_rot = 3
    !> Condition kind: velocity held at zero.
    integer, parameter :: dof_fixed = 1
    !> Condition kind: velocity imposed as value times a time function.
    integer, parameter :: dof_imposed = 2

    !> A condition on one DOF of one disk.
    type :: dof_condition_t
        !> Disk index.
        integer :: particle = 0
        !> DOF (dof_x, dof_y, dof_rot).
        integer :: dof = 0
        !> dof_fixed or dof_imposed.
        integer :: kind = dof_fixed
        !> Imposed velocity amplitude [m/s or rad/s].
        real(wp) :: value = 0.0_wp
        !> Time function index (0 = constant 1).
        integer :: func = 0
    end type dof_condition_t

    !> A load on one DOF of one disk: force [N/m] or torque [N] per unit thickness.
    type :: particle_load_t
        !> Disk index.
        integer :: particle = 0
        !> DOF (dof_x, dof_y, dof_rot).
        integer :: dof = 0
        !> Amplitude.
        real(wp) :: value = 0.0_wp
        !> Time function index (0 = constant 1).
        integer :: func = 0
    end type particle_load_t

    !> The disks: state, properties, conditions and loads (SI units, per unit thickness).
    type :: particles_t
        !> Number of disks.
        integer :: n = 0
        !> Centre coordinates [m].
        real(wp), allocatable :: x(:), y(:)
        !> Rotation angle [rad].
        real(wp), allocatable :: rot(:)
        !> Translational velocity [m/s].
        real(wp), allocatable :: vx(:), vy(:)
        !> Angular velocity [rad/s].
        real(wp), allocatable :: w(:)
        !> Radius [m].
        real(wp), allocatable :: radius(:)
        !> Mass per unit thickness [kg/m].
        real(wp), allocatable :: mass(:)
        !> Moment of inertia per unit thickness [kg m].
        real(wp), allocatable :: inertia(:)
        !> Material index (into the material table).
        integer, allocatable :: mat(:)
        !> Gravity acceleration [m/s^2].
        real(wp) :: gravity(2) = [0.0_wp, 0.0_wp]
        !> Number of DOF conditions in use.
        integer :: n_conditions = 0
        !> DOF conditions (first n_conditions used; a later condition overrides an earlier one).
        type(dof_condition_t), allocatable :: conditions(:)
        !> Number of loads in use.
        integer :: n_loads = 0
        !> Loads (first n_loads used).
        type(particle_load_t), allocatable :: loads(:)
        !> Time functions referenced by conditions and loads.
        type(time_function_slot_t), allocatable :: functions(:)
    end type particles_t

contains

    !> Append disks at rest; mass and inertia from radius and density.
    subroutine particles_add_disks(p, x, y, radius, density, error, mat)
        !> Disks to extend.
        type(particles_t), intent(inout) :: p
        !> Centres [m].
        real(wp), intent(in) :: x(:), y(:)
        !> Radii [m] (> 0).
        real(wp), intent(in) :: radius(:)
        !> Density [kg/m^3] (> 0): one value for all, or one per disk.
        real(wp), intent(in) :: density(:)
        !> Error if sizes disagree or a radius or density is not positive.
        type(error_t), allocatable, intent(out) :: error
        !> Material index of the new disks (default 1).
        integer, intent(in), optional :: mat
        integer :: m
        real(wp), allocatable :: rho(:), mass(:)
        m = size(x)
        if (size(y) /= m .or. size(radius) /= m .or. (size(density) /= m .and. size(density) /= 1)) then
            call make_internal_error(error, 'particles_add_disks', 'x, y, radius, density sizes differ')
            return
        end if
        if (any(radius <= 0.0_wp) .or. any(density <= 0.0_wp)) then
            call make_error(error, 'particles_add_disks: radius and density must be > 0')
            return
        end if
        if (size(density) == 1) then
            allocate (rho(m), source=density(1))
        else
            rho = density
        end if
        mass = rho*pi*radius**2
        call grow_state(p, m)
        p%x = [p%x, x]
        p%y = [p%y, y]
        p%radius = [p%radius, radius]
        p%mass = [p%mass, mass]
        p%inertia = [p%inertia, 0.5_wp*mass*radius**2]
        if (present(mat)) then
            p%mat(p%n + 1:p%n + m) = mat
        else
            p%mat(p%n + 1:p%n + m) = 1
        end if
        p%n = p%n + m
    end subroutine particles_add_disks

    !> Extend the state arrays (those not rebuilt by concatenation) by m disks at rest.
    subroutine grow_state(p, m)
        type(particles_t), intent(inout) :: p
        integer, intent(in) :: m
        if (.not. allocated(p%x)) then
            allocate (p%x(0), p%y(0), p%radius(0), p%mass(0), p%inertia(0))
            allocate (p%rot(0), p%vx(0), p%vy(0), p%w(0), p%mat(0))
        end if
        p%rot = [p%rot, spread(0.0_wp, 1, m)]
        p%vx = [p%vx, spread(0.0_wp, 1, m)]
        p%vy = [p%vy, spread(0.0_wp, 1, m)]
        p%w = [p%w, spread(0.0_wp, 1, m)]
        p%mat = [p%mat, spread(1, 1, m)]
    end subroutine grow_state

    !> Fix one DOF of a disk (velocity held at zero).
    subroutine particles_fix(p, i, dof, error)
        !> Disks.
        type(particles_t), intent(inout) :: p
        !> Disk index.
        integer, intent(in) :: i
        !> DOF (dof_x, dof_y, dof_rot).
        integer, intent(in) :: dof
        !> Error if the disk or DOF does not exist.
        type(error_t), allocatable, intent(out) :: error
        call add_condition(p, dof_condition_t(particle=i, dof=dof, kind=dof_fixed), error)
    end subroutine particles_fix

    !> Impose the velocity of one DOF of a disk: value * f(t).
    subroutine particles_impose_velocity(p, i, dof, value, error, func)
        !> Disks.
        type(particles_t), intent(inout) :: p
        !> Disk index.
        integer, intent(in) :: i
        !> DOF (dof_x, dof_y, dof_rot).
        integer, intent(in) :: dof
        !> Velocity amplitude [m/s or rad/s].
        real(wp), intent(in) :: value
        !> Error if the disk, DOF or time function does not exist.
        type(error_t), allocatable, intent(out) :: error
        !> Time function index (default 0 = constant 1).
        integer, intent(in), optional :: func
        type(dof_condition_t) :: c
        c = dof_condition_t(particle=i, dof=dof, kind=dof_imposed, value=value)
        if (present(func)) c%func = func
        call add_condition(p, c, error)
    end subroutine particles_impose_velocity

    !> Add a load value * f(t) on one DOF of a disk.
    subroutine particles_add_load(p, i, dof, value, error, func)
        !> Disks.
        type(particles_t), intent(inout) :: p
        !> Disk index.
        integer, intent(in) :: i
        !> DOF (dof_x, dof_y, dof_rot).
        integer, intent(in) :: dof
        !> Force [N/m] or torque [N] amplitude.
        real(wp), intent(in) :: value
        !> Error if the disk, DOF or time function does not exist.
        type(error_t), allocatable, intent(out) :: error
        !> Time function index (default 0 = constant 1).
        integer, intent(in), optional :: func
        type(particle_load_t), allocatable :: tmp(:)
        integer :: f
        f = 0
        if (present(func)) f = func
        call check_target(p, i, dof, f, 'particles_add_load', error)
        if (allocated(error)) return
        if (.not. allocated(p%loads)) allocate (p%loads(4))
        if (p%n_loads == size(p%loads)) then
            allocate (tmp(2*size(p%loads)))
            tmp(1:p%n_loads) = p%loads(1:p%n_loads)
            call move_alloc(tmp, p%loads)
        end if
        p%n_loads = p%n_loads + 1
        p%loads(p%n_loads) = particle_load_t(particle=i, dof=dof, value=value, func=f)
    end subroutine particles_add_load

    !> Append a condition (capacity doubles as needed).
    subroutine add_condition(p, c, error)
        type(particles_t), intent(inout) :: p
        type(dof_condition_t), intent(in) :: c
        type(error_t), allocatable, intent(out) :: error
        type(dof_condition_t), allocatable :: tmp(:)
        call check_target(p, c%particle, c%dof, c%func, 'particle condition', error)
        if (allocated(error)) return
        if (.not. allocated(p%conditions)) allocate (p%conditions(4))
        if (p%n_conditions == size(p%conditions)) then
            allocate (tmp(2*size(p%conditions)))
            tmp(1:p%n_conditions) = p%conditions(1:p%n_conditions)
            call move_alloc(tmp, p%conditions)
        end if
        p%n_conditions = p%n_conditions + 1
        p%conditions(p%n_conditions) = c
    end subroutine add_condition

    !> Check that disk i, DOF and time function index exist.
    subroutine check_target(p, i, dof, func, what, error)
        type(particles_t), intent(in) :: p
        integer, intent(in) :: i, dof, func
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        integer :: nf
        character(len=80) :: buf
        nf = 0
        if (allocated(p%functions)) nf = size(p%functions)
        if (i < 1 .or. i > p%n) then
            write (buf, '(a,i0,a,i0,a)') 'disk ', i, ' does not exist (1..', p%n, ')'
        else if (dof < dof_x .or. dof > dof_rot) then
            write (buf, '(a,i0,a)') 'DOF ', dof, ' does not exist (1 = x, 2 = y, 3 = rotation)'
        else if (func < 0 .or. func > nf) then
            write (buf, '(a,i0,a,i0,a)') 'time function ', func, ' does not exist (0..', nf, ')'
        else
            return
        end if
        call make_error(error, what//': '//trim(buf))
    end subroutine check_target

    !> Value of time function `func` at time t (0 means the constant 1).
    pure real(wp) function particles_time_function(p, func, t) result(f)
        !> Disks (owner of the functions).
        type(particles_t), intent(in) :: p
        !> Function index.
        integer, intent(in) :: func
        !> Time [s].
        real(wp), intent(in) :: t
        if (func == 0) then
            f = 1.0_wp
        else
            f = p%functions(func)%fn%value(t)
        end if
    end function particles_time_function

    !> Inverse mass per DOF, (3, n): zero on fixed and imposed DOFs.
    pure subroutine particles_inverse_mass(p, im)
        !> Disks.
        type(particles_t), intent(in) :: p
        !> Inverse mass (1/m, 1/m, 1/I) per disk.
        real(wp), intent(out) :: im(:, :)
        integer :: k
        im(1, :) = 1.0_wp/p%mass(1:p%n)
        im(2, :) = im(1, :)
        im(3, :) = 1.0_wp/p%inertia(1:p%n)
        do k = 1, p%n_conditions
            im(p%conditions(k)%dof, p%conditions(k)%particle) = 0.0_wp
        end do
    end subroutine particles_inverse_mass

    !> Overwrite the velocity of every constrained DOF with its value at time t.
    pure subroutine particles_constrained_velocity(p, t, vel)
        !> Disks.
        type(particles_t), intent(in) :: p
        !> Time [s].
        real(wp), intent(in) :: t
        !> Velocities (3, n).
        real(wp), intent(inout) :: vel(:, :)
        integer :: k
        type(dof_condition_t) :: c
        do k = 1, p%n_conditions
            c = p%conditions(k)
            if (c%kind == dof_fixed) then
                vel(c%dof, c%particle) = 0.0_wp
            else
                vel(c%dof, c%particle) = c%value*particles_time_function(p, c%func, t)
            end if
        end do
    end subroutine particles_constrained_velocity

    !> Generalised forces (3, n) of the loads at time t (the weight is added by the time stepper).
    pure subroutine particles_forces(p, t, f)
        !> Disks.
        type(particles_t), intent(in) :: p
        !> Time [s].
        real(wp), intent(in) :: t
        !> Forces and torques per unit thickness (3, n).
        real(wp), intent(out) :: f(:, :)
        integer :: k
        type(particle_load_t) :: l
        f = 0.0_wp
        do k = 1, p%n_loads
            l = p%loads(k)
            f(l%dof, l%particle) = f(l%dof, l%particle) + l%value*particles_time_function(p, l%func, t)
        end do
    end subroutine particles_forces

    !> Kinetic energy per unit thickness [J/m].
    pure real(wp) function particles_kinetic_energy(p) result(e)
        !> Disks.
        type(particles_t), intent(in) :: p
        e = 0.5_wp*sum(p%mass(1:p%n)*(p%vx(1:p%n)**2 + p%vy(1:p%n)**2) + p%inertia(1:p%n)*p%w(1:p%n)**2)
    end function particles_kinetic_energy

    !> Gravity potential energy -m g.x per unit thickness [J/m] (zero at the origin).
    pure real(wp) function particles_potential_energy(p) result(e)
        !> Disks.
        type(particles_t), intent(in) :: p
        e = -sum(p%mass(1:p%n)*(p%gravity(1)*p%x(1:p%n) + p%gravity(2)*p%y(1:p%n)))
    end function particles_potential_energy

    !> Memory held by the disk arrays, conditions and loads [bytes].
    pure integer(i8) function particles_bytes(p) result(b)
        !> Disks.
        type(particles_t), intent(in) :: p
        b = 0_i8
        if (allocated(p%x)) b = 8_i8*(size(p%x) + size(p%y) + size(p%rot) + size(p%vx) + size(p%vy) + size(p%w) &
                                      + size(p%radius) + size(p%mass) + size(p%inertia)) + 4_i8*size(p%mat)
        if (allocated(p%conditions)) b = b + size(p%conditions)*storage_size(p%conditions)/8
        if (allocated(p%loads)) b = b + size(p%loads)*storage_size(p%loads)/8
    end function particles_bytes

    !> Linear momentum (px, py) per unit thickness [kg/s].
    pure function particles_momentum(p) result(q)
        !> Disks.
        type(particles_t), intent(in) :: p
        real(wp) :: q(2)
        q(1) = sum(p%mass(1:p%n)*p%vx(1:p%n))
        q(2) = sum(p%mass(1:p%n)*p%vy(1:p%n))
    end function particles_momentum
end module dem_particles
