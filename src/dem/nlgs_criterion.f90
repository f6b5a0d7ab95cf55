!> Stopping tests of the NLGS sweeps (`[solver] criterion`): the extensions of
!> dem_nlgs::nlgs_criterion_t, the error of the iterate that is compared with the tolerance
!> (dem_nlgs, module header). lmgc90_criterion_t: the LMGC90-like convergence norm of the
!> sweeps itself. siconos_criterion_t: the Siconos error (doc/theory.md 4.5), evaluated from
!> the velocities the sweeps keep up to date (dem_nlgs::siconos_ratio) only after the sweeps
!> where it may be near the tolerance (siconos_period, siconos_margin), and once below it again
!> in full (dem_nlgs::siconos_error), which alone stops the sweeps.
module dem_nlgs_criterion
    use core_kinds, only: wp
    use dem_contacts, only: contact_set_t
    use dem_nlgs, only: nlgs_criterion_t, siconos_error, siconos_ratio
    implicit none
    private
    public :: lmgc90_criterion_t, siconos_criterion_t

    !> Siconos criterion: the error is evaluated at least every siconos_period sweeps, and at
    !> every sweep once the norm of the sweeps times their last measured ratio is below
    !> siconos_margin times the tolerance and the norm is below its value at the last
    !> evaluation (which found the error above the tolerance: while the norm has not fallen
    !> since, the estimate has not either). Without that second condition a step where the
    !> error hangs just above the tolerance for hundreds of sweeps (the impacts of the
    !> 200-disk deposit) evaluated it at every one of them: 45 % of the sweeps on seed 8,
    !> 25 % with it, and 0.83 against 0.87 ms per step over 24 layouts (doc/performance.md,
    !> "Fewer evaluations of the Siconos error"). A margin of 2 rather than 4: on the 200-disk deposit
    !> over 24 layouts 0.789 against 0.813 ms per step, on the 2 000-disk one over 6 layouts
    !> 18.7 against 20.6 ms, with the same sweeps on average (doc/performance.md,
    !> "Explicit-shape kernels"); the deposits are chaotic, so one layout does not decide.
    integer, parameter :: siconos_period = 8
    real(wp), parameter :: siconos_margin = 2.0_wp

    !> The LMGC90-like convergence norm of the sweeps (dem_nlgs, module header), what a solve
    !> without a criterion uses.
    type, extends(nlgs_criterion_t) :: lmgc90_criterion_t
    contains
        !> 'lmgc90'.
        procedure :: name => lmgc90_name
        !> Nothing to set up.
        procedure :: begin => lmgc90_begin
        !> The norm itself, always exact.
        procedure :: measure => lmgc90_measure
    end type lmgc90_criterion_t

    !> The Siconos error (nlgs_siconos_error), evaluated only where it may be near the
    !> tolerance (siconos_period, siconos_margin).
    type, extends(nlgs_criterion_t) :: siconos_criterion_t
        !> The active contacts of the solve, in increasing order.
        integer, allocatable, private :: act(:)
        !> Contacts held as bilateral constraints in the solve (the members of a block),
        !> measured by the equality u = 0 on their locked components (siconos_ratio);
        !> size 0 when none.
        logical, allocatable, private :: held(:)
        !> Ratio of the Siconos error to the norm of the sweeps at its last evaluation, that
        !> norm, and that sweep.
        real(wp), private :: per_norm = 0.0_wp, norm_evaluated = huge(1.0_wp)
        !> See `per_norm`.
        integer, private :: last_evaluation = 0
    contains
        !> 'siconos'.
        procedure :: name => siconos_name
        !> The active contacts, no evaluation yet.
        procedure :: begin => siconos_begin
        !> The error where it may be near the tolerance, an estimate elsewhere.
        procedure :: measure => siconos_measure
        !> True.
        procedure :: is_siconos_error => siconos_is_siconos_error
    end type siconos_criterion_t

contains

    !> 'lmgc90'.
    pure function lmgc90_name(self) result(name)
        !> The criterion.
        class(lmgc90_criterion_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'lmgc90'
    end function lmgc90_name

    !> Nothing to set up.
    subroutine lmgc90_begin(self, cs, held)
        !> The criterion.
        class(lmgc90_criterion_t), intent(inout) :: self
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Contacts held (not used: the norm of the sweeps measures the block by its own share).
        logical, intent(in), optional :: held(:)
    end subroutine lmgc90_begin

    !> The convergence norm of the sweeps is the error, exact.
    subroutine lmgc90_measure(self, s, needed, tol, cs, im, vfree, vel, vwork, bilateral, nq, error, evaluated)
        !> The criterion.
        class(lmgc90_criterion_t), intent(inout) :: self
        !> Sweeps done.
        integer, intent(in) :: s
        !> The exact error is needed.
        logical, intent(in) :: needed
        !> Tolerance.
        real(wp), intent(in) :: tol
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Inverse mass, free velocities and velocities (3, n_disks).
        real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :)
        !> Work array (3, n_disks).
        real(wp), intent(inout) :: vwork(:, :)
        !> Bilateral constraints changed the velocities.
        logical, intent(in) :: bilateral
        !> |q| of the Siconos error.
        real(wp), intent(in) :: nq
        !> The convergence norm, kept.
        real(wp), intent(inout) :: error
        !> True.
        logical, intent(out) :: evaluated
        evaluated = .true.
    end subroutine lmgc90_measure

    !> 'siconos'.
    pure function siconos_name(self) result(name)
        !> The criterion.
        class(siconos_criterion_t), intent(in) :: self
        character(len=:), allocatable :: name
        name = 'siconos'
    end function siconos_name

    !> The active contacts, in increasing order (the running error runs over them), and those
    !> held; no evaluation yet.
    subroutine siconos_begin(self, cs, held)
        !> The criterion (the copy of a solve).
        class(siconos_criterion_t), intent(inout) :: self
        !> Contacts (activity set).
        type(contact_set_t), intent(in) :: cs
        !> Contacts held as bilateral constraints (a block's members; none when absent).
        logical, intent(in), optional :: held(:)
        integer :: k
        self%act = pack([(k, k=1, cs%n)], cs%active(1:cs%n))
        if (present(held)) then
            self%held = held(1:cs%n)
        else
            if (allocated(self%held)) deallocate (self%held)
            allocate (self%held(0))
        end if
        self%per_norm = 0.0_wp
        self%norm_evaluated = huge(1.0_wp)
        self%last_evaluation = 0
    end subroutine siconos_begin

    !> The Siconos error after sweep s, evaluated when it may be near the tolerance (the norm
    !> of the sweeps times their last measured ratio), every siconos_period sweeps, and where
    !> the solve needs it (the cap, a safeguard); from the velocities the sweeps keep up to
    !> date, and below the tolerance again from u = W r + q in full, which alone stops the
    !> sweeps. Elsewhere an estimate (the norm times the last ratio), which does not stop
    !> them.
    subroutine siconos_measure(self, s, needed, tol, cs, im, vfree, vel, vwork, bilateral, nq, error, evaluated)
        !> The criterion (the copy of a solve).
        class(siconos_criterion_t), intent(inout) :: self
        !> Sweeps done.
        integer, intent(in) :: s
        !> The solve needs the exact error (the cap, a safeguard).
        logical, intent(in) :: needed
        !> Tolerance.
        real(wp), intent(in) :: tol
        !> Contacts (reactions).
        type(contact_set_t), intent(in) :: cs
        !> Inverse mass, free velocities and velocities (3, n_disks).
        real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :)
        !> Work array (3, n_disks).
        real(wp), intent(inout) :: vwork(:, :)
        !> Bilateral constraints changed the velocities.
        logical, intent(in) :: bilateral
        !> |q| of the Siconos error.
        real(wp), intent(in) :: nq
        !> The norm of the sweeps in, the Siconos error (or its estimate) out.
        real(wp), intent(inout) :: error
        !> The error is exact.
        logical, intent(out) :: evaluated
        real(wp) :: norm
        evaluated = s - self%last_evaluation >= siconos_period .or. needed &
                    .or. (error*self%per_norm <= siconos_margin*tol .and. error < self%norm_evaluated)
        if (evaluated) then
            norm = error
            self%norm_evaluated = norm
            if (size(self%held) > 0) then
                error = siconos_ratio(cs, self%act, vel, nq, self%held)
            else
                error = siconos_ratio(cs, self%act, vel, nq)
            end if
            self%per_norm = 0.0_wp
            if (norm > 0.0_wp) self%per_norm = error/norm
            self%last_evaluation = s
            if (error <= tol) then
                if (size(self%held) > 0) then
                    error = siconos_error(cs, im, vfree, vel, vwork, bilateral, nq, self%held)
                else
                    error = siconos_error(cs, im, vfree, vel, vwork, bilateral, nq)
                end if
            end if
        else
            error = error*self%per_norm
        end if
    end subroutine siconos_measure

    !> True: the error that stops the sweeps is the Siconos error of the final state.
    pure logical function siconos_is_siconos_error(self) result(yes)
        !> The criterion.
        class(siconos_criterion_t), intent(in) :: self
        yes = .true.
    end function siconos_is_siconos_error
end module dem_nlgs_criterion
