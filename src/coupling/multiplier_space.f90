!> Multiplier spaces of the Arlequin coupling (doc/theory.md sections 6.4, 6.6, 6.9): where the
!> Lagrange multipliers live and which part of the per-row residual e (n_rows: one row per
!> coupled DOF, x, y and optionally the rotation of each coupled point) they impose.
!>
!> Every space is described by a linear map Pi (n_mult, n_rows): the constraint is
!> Pi e = 0, the coupled DOFs receive the forces mu = Pi^T lambda_m, and with the row
!> matrix A (A mu = -g when every row is imposed) the multipliers solve A_m lambda_m = -Pi g,
!> A_m = Pi A Pi^T. The rows' solves therefore use B = Pi^T A_m^-1 Pi in place of A^-1, and
!> lambda_m = A_m^-1 Pi A mu recovers the multipliers from the row forces.
!> - `disk_space_t` (per coupled DOF, Pi = I, the reference work): B = A^-1, lambda_m = mu.
!>   It is kept as its own extension, not as a mediator with Pi = I, so that its arithmetic
!>   (one solve with A) stays that of the per-DOF coupling.
!> - `mediator_space_t` (multipliers on FE nodes of the overlap, Bauman, Ben Dhia et al.
!>   2008): Pi is given by its builder (beam hat functions, or the 2D shape functions of the
!>   overlap's FE nodes at the coupled points, possibly with an H1 pairing, see
!>   coupling_operator2d); only Pi e = 0 is imposed, the disks may move in the kernel of Pi.
!> Adding a space adds an extension of `multiplier_space_t`, not a branch in the coupled step.
module coupling_multiplier_space
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: sci_to_str
    use core_linalg, only: dense_spd_t, symmetrize
    implicit none
    private
    public :: multiplier_space_t, disk_space_t, mediator_space_t, make_mediator_space
    public :: comp_rotation

    !> Component code of rotation rows (x = 1, y = 2, rotation = 3, as dof_x, dof_y, dof_rot).
    integer, parameter :: comp_rotation = 3

    !> A multiplier space over n_rows coupled DOFs (see the module description).
    type, abstract :: multiplier_space_t
        !> Number of coupled rows (coupled DOFs).
        integer :: n_rows = 0
        !> Number of multipliers.
        integer :: n_mult = 0
        !> Component (1 = x, 2 = y, comp_rotation) of each multiplier (n_mult).
        integer, allocatable :: comp(:)
    contains
        !> B = Pi^T A_m^-1 Pi (n_rows, n_rows) from the factored row matrix A; prepares the
        !> recovery of the multipliers.
        procedure(space_inverse_iface), deferred :: inverse
        !> Multipliers lambda_m (n_mult) from the row forces mu (n_rows).
        procedure(space_recover_iface), deferred :: recover
        !> Pi v (n_mult) for a row vector v (n_rows).
        procedure(space_project_iface), deferred :: project
        !> Pi^T lambda_m (n_rows).
        procedure(space_project_iface), deferred :: lift
        !> True when the multipliers impose only a projection of the per-row residual.
        procedure(space_flag_iface), deferred :: projected
        !> Norm of the imposed part Pi v over the translation (or rotation) multipliers.
        procedure :: constraint_norm => space_constraint_norm
    end type multiplier_space_t

    abstract interface
        !> B from the factored A (see the type).
        subroutine space_inverse_iface(self, a, b, error)
            import :: multiplier_space_t, dense_spd_t, wp, error_t
            !> The space; stores what the recovery needs.
            class(multiplier_space_t), intent(inout) :: self
            !> Row matrix A (n_rows, n_rows), factored.
            type(dense_spd_t), intent(in) :: a
            !> B (n_rows, n_rows), exactly symmetric.
            real(wp), allocatable, intent(out) :: b(:, :)
            !> Set when A_m is singular or a solve fails.
            type(error_t), allocatable, intent(out) :: error
        end subroutine space_inverse_iface

        !> lambda_m from the row forces mu.
        pure subroutine space_recover_iface(self, mu, lambda_m)
            import :: multiplier_space_t, wp
            !> The space (after `inverse`).
            class(multiplier_space_t), intent(in) :: self
            !> Row forces (n_rows).
            real(wp), intent(in) :: mu(:)
            !> Multipliers (n_mult).
            real(wp), intent(out) :: lambda_m(:)
        end subroutine space_recover_iface

        !> A linear map of the space applied to a vector.
        pure function space_project_iface(self, v) result(w)
            import :: multiplier_space_t, wp
            !> The space.
            class(multiplier_space_t), intent(in) :: self
            !> Input vector.
            real(wp), intent(in) :: v(:)
            !> Result.
            real(wp), allocatable :: w(:)
        end function space_project_iface

        !> A property of the space.
        pure logical function space_flag_iface(self)
            import :: multiplier_space_t
            !> The space.
            class(multiplier_space_t), intent(in) :: self
        end function space_flag_iface
    end interface

    !> One multiplier per coupled DOF (Pi = I).
    type, extends(multiplier_space_t) :: disk_space_t
    contains
        procedure :: inverse => disk_inverse
        procedure :: recover => disk_recover
        procedure :: project => disk_identity
        procedure :: lift => disk_identity
        procedure :: projected => disk_projected
    end type disk_space_t

    !> Multipliers on mediator nodes: a given Pi (n_mult, n_rows), dense (the overlap is small).
    type, extends(multiplier_space_t) :: mediator_space_t
        !> Pi (n_mult, n_rows).
        real(wp), allocatable :: pi(:, :)
        !> R = A_m^-1 Pi A (n_mult, n_rows), set by `inverse`.
        real(wp), allocatable :: recovery(:, :)
    contains
        procedure :: inverse => mediator_inverse
        procedure :: recover => mediator_recover
        procedure :: project => mediator_project
        procedure :: lift => mediator_lift
        procedure :: projected => mediator_projected
    end type mediator_space_t

    interface disk_space_t
        module procedure make_disk_space
    end interface disk_space_t

contains

    !> The per-DOF space over rows of the given components (1 = x, 2 = y, comp_rotation).
    pure function make_disk_space(row_comp) result(space)
        !> Component of each row (n_rows).
        integer, intent(in) :: row_comp(:)
        type(disk_space_t) :: space
        space%n_rows = size(row_comp)
        space%n_mult = size(row_comp)
        space%comp = row_comp
    end function make_disk_space

    !> The mediator space of a given Pi and the component of each multiplier.
    subroutine make_mediator_space(pi, comp, space, error)
        !> Pi (n_mult, n_rows).
        real(wp), intent(in) :: pi(:, :)
        !> Component of each multiplier (n_mult).
        integer, intent(in) :: comp(:)
        !> The space.
        type(mediator_space_t), intent(out) :: space
        !> Set when sizes disagree or there are more multipliers than rows.
        type(error_t), allocatable, intent(out) :: error
        if (size(comp) /= size(pi, 1)) then
            call make_error(error, 'multiplier space: one component per row of Pi is needed')
            return
        end if
        if (size(pi, 1) > size(pi, 2)) then
            call make_error(error, 'multiplier space: more mediator multipliers than coupled '// &
                            'DOFs (Pi A Pi^T would be singular): couple more disks or use '// &
                            'multipliers on the disks')
            return
        end if
        space%n_mult = size(pi, 1)
        space%n_rows = size(pi, 2)
        space%pi = pi
        space%comp = comp
    end subroutine make_mediator_space

    !> Euclidean norm of Pi v over the translation multipliers (rotation = false) or the
    !> rotation ones.
    pure real(wp) function space_constraint_norm(self, v, rotation) result(nrm)
        !> The space.
        class(multiplier_space_t), intent(in) :: self
        !> Row vector (n_rows).
        real(wp), intent(in) :: v(:)
        !> Norm over the rotation multipliers instead of the translation ones.
        logical, intent(in) :: rotation
        nrm = norm2(merge(self%project(v), 0.0_wp, (self%comp == comp_rotation) .eqv. rotation))
    end function space_constraint_norm

    !> B = A^-1 (from the factor).
    subroutine disk_inverse(self, a, b, error)
        class(disk_space_t), intent(inout) :: self
        type(dense_spd_t), intent(in) :: a
        real(wp), allocatable, intent(out) :: b(:, :)
        type(error_t), allocatable, intent(out) :: error
        call a%inverse(b, error)
    end subroutine disk_inverse

    !> lambda = mu.
    pure subroutine disk_recover(self, mu, lambda_m)
        class(disk_space_t), intent(in) :: self
        real(wp), intent(in) :: mu(:)
        real(wp), intent(out) :: lambda_m(:)
        lambda_m = mu
    end subroutine disk_recover

    !> Pi = Pi^T = I.
    pure function disk_identity(self, v) result(w)
        class(disk_space_t), intent(in) :: self
        real(wp), intent(in) :: v(:)
        real(wp), allocatable :: w(:)
        w = v
    end function disk_identity

    !> Every row is imposed.
    pure logical function disk_projected(self)
        class(disk_space_t), intent(in) :: self
        disk_projected = .false.
    end function disk_projected

    !> A_m = Pi A Pi^T (factored), B = Pi^T A_m^-1 Pi, R = A_m^-1 Pi A.
    subroutine mediator_inverse(self, a, b, error)
        class(mediator_space_t), intent(inout) :: self
        type(dense_spd_t), intent(in) :: a
        real(wp), allocatable, intent(out) :: b(:, :)
        type(error_t), allocatable, intent(out) :: error
        type(dense_spd_t) :: am
        real(wp), allocatable :: p(:, :)
        real(wp) :: rcond
        associate (pi => self%pi)
            call am%init(self%n_mult)
            am%a = matmul(pi, matmul(a%a, transpose(pi)))
            call symmetrize(am%a)
            call am%factor(error)
            ! Which of the two tests below sees a nearly singular A_m first depends on round-off
            ! (the BLAS kernels of the machine): on one machine the factor of the H1 pairing's
            ! A_m at h1_length = 1e3 m succeeds with rcond ~1e-20, on another it fails. Both say
            ! the same thing to the user.
            if (allocated(error)) then
                error%message = 'coupling: multipliers = nodes: A_m = Pi A Pi^T is singular to working '// &
                                'precision ('//error%message//')'
                return
            end if
            ! A factor of a nearly singular A_m can succeed on round-off (the H1 pairing with a
            ! long h1_length) and the run then blows up steps later. Below machine epsilon A_m is
            ! singular to working precision (LAPACK's test in xPOSVX). Measured on
            ! input/coupled2d_block.dat in rigid motion, elements of 0.25 m: h1_length = 64 m
            ! (rcond 1.9e-15) keeps the velocity residual at 1.8e-10 m/s, 256 m (7.5e-18) at
            ! 2.7e-9 m/s, 1000 m (1.3e-20) blows up (disks through each other at step 15).
            rcond = am%rcond()
            if (rcond < epsilon(1.0_wp)) then
                call make_error(error, 'coupling: multipliers = nodes: A_m = Pi A Pi^T is singular to '// &
                                'working precision (reciprocal condition number '//sci_to_str(rcond, 2)// &
                                ', below machine epsilon '//sci_to_str(epsilon(1.0_wp), 2)//')')
                return
            end if
            p = pi
            call am%solve(p, error)
            if (allocated(error)) return
            b = matmul(transpose(pi), p)
            call symmetrize(b)
            self%recovery = matmul(p, a%a)
            ! A factor can succeed on entries out of scale and still give an overflowing inverse
            if (.not. (all(ieee_is_finite(b)) .and. all(ieee_is_finite(self%recovery)))) then
                call make_error(error, 'coupling: multipliers = nodes: A_m = Pi A Pi^T is out of '// &
                                'scale: its inverse is not finite')
                return
            end if
        end associate
    end subroutine mediator_inverse

    !> lambda_m = R mu.
    pure subroutine mediator_recover(self, mu, lambda_m)
        class(mediator_space_t), intent(in) :: self
        real(wp), intent(in) :: mu(:)
        real(wp), intent(out) :: lambda_m(:)
        lambda_m = matmul(self%recovery, mu)
    end subroutine mediator_recover

    !> Pi v.
    pure function mediator_project(self, v) result(w)
        class(mediator_space_t), intent(in) :: self
        real(wp), intent(in) :: v(:)
        real(wp), allocatable :: w(:)
        w = matmul(self%pi, v)
    end function mediator_project

    !> Pi^T lambda_m.
    pure function mediator_lift(self, v) result(w)
        class(mediator_space_t), intent(in) :: self
        real(wp), intent(in) :: v(:)
        real(wp), allocatable :: w(:)
        w = matmul(transpose(self%pi), v)
    end function mediator_lift

    !> Only Pi e is imposed.
    pure logical function mediator_projected(self)
        class(mediator_space_t), intent(in) :: self
        mediator_projected = .true.
    end function mediator_projected
end module coupling_multiplier_space
