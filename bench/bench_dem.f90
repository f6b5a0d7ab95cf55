!> Speed and memory of the discrete-element kernel (issue 3, "Speed").
!>
!> For N = 1e3, 1e4, 1e5 disks: a dense packing at rest in a box under gravity (hexagonal
!> lattice of touching disks of radius 1 mm, densities drawn at random in [1250, 3750] kg/m^3
!> with a fixed seed, so that the weight is carried by an irregular force network through
!> every contact), mu = 0.5, e = 0, h = 1 ms, theta = 1/2, alert 5 % of the radius, NLGS
!> tolerance 1.666e-4 (LMGC90's default), at most 200 sweeps. After 10 steps,
!> max(5, 1e5/N) steps are timed. Printed per N:
!> contacts in the list and active, sweeps per step, wall-clock time per step of the detection
!> (broad + narrow phase + warm start; mean and best step, the machine being shared) and of the
!> solver (laws, frames, NLGS, residual), contact
!> updates per second (active contacts x sweeps / solver time) and bytes per particle (all
!> arrays of the system at their allocated size).
!> Run: cmake --build <build> --target bench_dem && <build>/bench/bench_dem
program bench_dem
    use, intrinsic :: iso_fortran_env, only: output_unit
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use dem_random, only: rng_t, rng_seed, rng_uniform_in
    use dem_particles, only: particles_add_disks
    use dem_generators, only: generate_hex_lattice
    use dem_walls, only: walls_add
    use dem_materials, only: materials_init, materials_set_pair
    use dem_moreau_jean, only: dem_system_t, mj_init, mj_step, dem_system_bytes
    implicit none
    integer, parameter :: sizes(3) = [1000, 10000, 100000]
    integer, parameter :: n_settle = 10
    real(wp) :: det_mean(size(sizes)), det_min(size(sizes))
    integer :: k
    write (output_unit, '(a)') '# DEM kernel benchmark (1 core): dense packing at rest under gravity'
    write (output_unit, '(a)') '#       N  contacts    active  sweeps/step   detect[ms] (min)   solve[ms]' &
        //'  updates/s  bytes/particle'
    do k = 1, size(sizes)
        call run_case(sizes(k), det_mean(k), det_min(k))
    end do
    write (output_unit, '(a, f6.2, a, f6.2, a)') '# detection time 1e5 / 1e4: ', det_mean(3)/det_mean(2), &
        ' (mean), ', det_min(3)/det_min(2), ' (best step)'
contains

    !> Build, settle, time and print one case.
    subroutine run_case(n, t_det, t_best)
        integer, intent(in) :: n
        real(wp), intent(out) :: t_det, t_best
        type(dem_system_t) :: sys
        integer(i8) :: updates, sweeps
        integer :: step, contacts, active, n_measure
        real(wp) :: t_sol, before
        ! at least 5 timed steps, and about 1e5 disk-steps, to average out timer noise
        n_measure = max(5, 100000/n)
        call build(sys, n)
        do step = 1, n_settle
            call mj_step(sys)
        end do
        sys%time_detection = 0.0_wp
        sys%time_solver = 0.0_wp
        updates = 0_i8
        sweeps = 0_i8
        t_best = huge(1.0_wp)
        do step = 1, n_measure
            before = sys%time_detection
            call mj_step(sys)
            t_best = min(t_best, sys%time_detection - before)
            updates = updates + sys%stats%updates
            sweeps = sweeps + sys%stats%sweeps
        end do
        contacts = sys%contacts%n
        active = sys%stats%n_active
        t_det = sys%time_detection/n_measure
        t_sol = sys%time_solver/n_measure
        write (output_unit, '(i9, 2i10, f13.1, f13.2, f7.2, f12.2, es11.3, i16)') sys%particles%n, contacts, &
            active, real(sweeps, wp)/n_measure, 1.0e3_wp*t_det, 1.0e3_wp*t_best, 1.0e3_wp*t_sol, &
            real(updates, wp)/sys%time_solver, dem_system_bytes(sys)/sys%particles%n
        flush (output_unit)
    end subroutine run_case

    !> Hexagonal packing of about n disks (square box), walls, law, scheme.
    subroutine build(sys, n)
        type(dem_system_t), intent(out) :: sys
        integer, intent(in) :: n
        real(wp), parameter :: r = 1.0e-3_wp
        real(wp), allocatable :: x(:), y(:), radius(:), density(:)
        type(error_t), allocatable :: error
        type(rng_t) :: rng
        real(wp) :: top
        integer :: nx, ny, i
        nx = nint(sqrt(n*sqrt(3.0_wp)/2.0_wp))
        ny = n/nx
        call generate_hex_lattice(nx, ny, 0.0_wp, 0.0_wp, r, 0.0_wp, x, y, radius, error)
        call rng_seed(rng, 42)
        allocate (density(size(x)))
        do i = 1, size(x)
            call rng_uniform_in(rng, 1250.0_wp, 3750.0_wp, density(i))
        end do
        call particles_add_disks(sys%particles, x, y, radius, density, error)
        top = maxval(y) + 10.0_wp*r
        call walls_add(sys%walls, -r, -r, 2.0_wp*r*nx + r, -r, error)
        call walls_add(sys%walls, -r, -r, -r, top, error)
        call walls_add(sys%walls, 2.0_wp*r*nx, -r, 2.0_wp*r*nx, top, error)
        call materials_init(sys%materials, 1, error)
        call materials_set_pair(sys%materials, 1, 1, 0.5_wp, 0.0_wp, 0.0_wp, error)
        sys%particles%gravity = [0.0_wp, -9.81_wp]
        sys%scheme%h = 1.0e-3_wp
        sys%scheme%alert = 0.05_wp*r
        sys%solver%tol = 1.666e-4_wp
        sys%solver%max_sweeps = 200
        call mj_init(sys, error)
        if (allocated(error)) error stop 'bench_dem: invalid setup'
    end subroutine build
end program bench_dem
