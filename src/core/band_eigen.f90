!> The lowest eigenpairs of a band pencil A x = lambda B x (A symmetric positive
!> semi-definite, e.g. a stiffness; B symmetric positive definite, e.g. a mass) by
!> shift-invert subspace iteration (Bathe, Finite Element Procedures, 11.6).
!>
!> Why not reduce the pencil to a standard problem (dsbgvx, or a Cholesky of B then a dense
!> eigensolver): that computes every eigenvalue with an absolute error of about
!> eps lambda_max, so the smallest ones lose eps lambda_max/lambda_1 of relative accuracy, and
!> lambda_max/lambda_1 grows as n_el^4 for a beam (a relative error of 1e-3 on the first
!> frequency of a 512-element cantilever); and with its eigenvectors it costs O(n^2). Iterating
!> with (A + sigma B)^-1 B instead makes the wanted eigenvalues the largest ones,
!> mu = 1/(lambda + sigma), and the lowest eigenvectors come out as accurate as the gaps
!> around them allow, whatever lambda_max, in O(n kd p) per iteration.
!>
!> The eigenvalues 1/mu - sigma still carry the backward error of the Cholesky factor of
!> A + sigma B, eps |U^T| |U|, which does not respect the structure of A (its null space, the
!> cancellations of its rows): on a string, A = tridiag(-1, 2, -1)/h with
!> lambda_max/lambda_1 = 1.9e7, lambda_1 is 1.2e-10 off (dsbgvx: 9.7e-8); on a 512-element
!> cantilever 1.5e-7 (dsbgvx: 1.5e-3). A caller that can evaluate x^T A x without cancellation
!> gets the eigenvalue to rounding from the Rayleigh quotient of the vector, whose error is
!> the square of the vector's (`fem_modal` does, from the elements' deformations).
!>
!> The iteration, with p = min(max(2 m, m + 8), n) vectors for m wanted:
!> 1. Xb = (A + sigma B)^-1 B X (band Cholesky, factored once);
!> 2. Xb made B-orthonormal (classical Gram-Schmidt, twice), the same combinations applied to
!>    B X = (A + sigma B) Xb and to B Xb, which are thus never recomputed;
!> 3. Rayleigh-Ritz on span(Xb) without forming A times a vector (that is where the
!>    eps lambda_max error would come back): Xb^T (A + sigma B) Xb = Xb^T B X, and the p x p
!>    problem (Xb^T B Xb) q = mu (Xb^T B X) q is solved for mu = 1/(lambda + sigma), the
!>    largest first (dsygv, accurate for the largest mu);
!> 4. X = Xb q, B-normalised, until every wanted Ritz pair has converged (`residual_tolerance`).
!> The operator (A + sigma B)^-1 B is self-adjoint in the B inner product, so a residual r
!> bounds the error of mu by |r|_B^2/gap (and by |r|_B), and the angle of the vector by
!> |r|_B/gap. The residual of a pair is taken without its components along the other Ritz
!> vectors: the rounding of the solve is amplified by 1/(lambda_k + sigma) along the lowest
!> modes, by 1/sigma along the null space of a singular A, and would set a floor to the other
!> pairs' residuals (1e-8 relative on a 16-element free beam) although the Rayleigh-Ritz step
!> removes it from the vectors.
!>
!> The shift: sigma = 0 when A can be factored (no zero eigenvalue); otherwise (rigid-body
!> motions free) the smallest of 1e-10, 1e-8, ... times max_i A_ii/B_ii that factors. The
!> diagonal ratios are Rayleigh quotients of unit vectors, so that scale is at most lambda_max:
!> the pivots of the rigid-body directions are then about 1e-10/(9 eps) = 5e4 times above the
!> singularity threshold of the factorisation (`band_spd_t%factor`), and lambda = 1/mu - sigma
!> loses only eps sigma of absolute accuracy (relative eps sigma/lambda).
!>
!> Both matrices are scaled by even powers of 2 to entries of order 1 (exact), so that no
!> product under- or overflows; lambda is scaled back at the end (an eigenvalue beyond the
!> range of real(wp) comes out infinite, for the caller to report).
module core_band_eigen
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_internal_error
    use core_linalg, only: band_spd_t, dense_generalized_eigen, even_exponent
    implicit none
    private
    public :: lowest_band_eigen

    !> The iteration has converged when every wanted Ritz pair (mu, x), |x|_B = 1, has a residual
    !> |(A + sigma B)^-1 B x - mu x|_B (without its components along the other Ritz vectors)
    !> below residual_tolerance mu, and either below residual_floor mu or no longer halving
    !> from one iteration to the next (its rounding floor). The eigenvalue error is then below
    !> residual_tolerance^2 mu/(relative gap), and the vector's angle below
    !> residual_tolerance/(relative gap).
    real(wp), parameter :: residual_tolerance = 1.0e-8_wp
    !> See `residual_tolerance`.
    real(wp), parameter :: residual_floor = 1.0e-12_wp
    !> Iterations allowed before giving up.
    integer, parameter :: max_iterations = 1000

contains

    !> The n_wanted smallest eigenvalues of A x = lambda B x, ascending, and their
    !> eigenvectors with X^T B X = I (the entry of largest magnitude of each made positive).
    subroutine lowest_band_eigen(a, b, n_wanted, lambda, vectors, error, shift, iterations)
        !> Matrix A (e.g. stiffness), symmetric positive semi-definite.
        type(band_spd_t), intent(in) :: a
        !> Matrix B (e.g. mass), same order, positive definite.
        type(band_spd_t), intent(in) :: b
        !> Number of eigenpairs wanted (1..n).
        integer, intent(in) :: n_wanted
        !> The n_wanted smallest eigenvalues, ascending (those of a singular A's null space are
        !> zero up to rounding, possibly slightly negative).
        real(wp), allocatable, intent(out) :: lambda(:)
        !> Eigenvectors (n, n_wanted), B-normalised.
        real(wp), allocatable, intent(out) :: vectors(:, :)
        !> Set on invalid sizes, a B that is not positive definite, or no convergence.
        type(error_t), allocatable, intent(out) :: error
        !> The shift sigma used, in the units of lambda (0 when A was factored).
        real(wp), intent(out), optional :: shift
        !> Number of iterations done.
        integer, intent(out), optional :: iterations
        type(band_spd_t) :: as, bs, shifted
        real(wp), allocatable :: x(:, :), y(:, :), xb(:, :), yb(:, :), khat(:, :), mhat(:, :), &
                                 mu(:), mu_new(:), q(:, :), r(:), mr(:), c(:), &
                                 residual(:), previous(:)
        real(wp) :: sigma
        integer :: n, p, ea, eb, iteration, j, k
        logical :: converged
        character(len=200) :: buf
        n = a%n
        if (b%n /= n .or. n_wanted < 1 .or. n_wanted > n) then
            call make_internal_error(error, 'lowest band eigenpairs', 'invalid sizes or number of eigenpairs')
            return
        end if
        p = min(max(2*n_wanted, n_wanted + 8), n)
        ea = even_exponent(a%ab)
        eb = even_exponent(b%ab)
        call as%init(n, max(a%kd, b%kd))
        call as%add_scaled(a, scale(1.0_wp, -ea))
        call bs%init(n, b%kd)
        call bs%add_scaled(b, scale(1.0_wp, -eb))
        call bs%factor(error)
        if (allocated(error)) then
            write (buf, '(a,i0,a)') 'generalized eigenproblem: the second matrix (mass) is not positive '// &
                'definite (equation ', bs%failed_equation, ')'
            deallocate (error)
            call make_error(error, trim(buf))
            return
        end if
        call choose_shift(as, bs, shifted, sigma, error)
        if (allocated(error)) return

        allocate (x(n, p), y(n, p), xb(n, p), yb(n, p), mu(p), r(n), mr(n), residual(n_wanted))
        allocate (previous(n_wanted), source=huge(1.0_wp))
        call start_vectors(x)
        do j = 1, p
            call bs%matvec(x(:, j), y(:, j))
        end do
        mu = 0.0_wp
        converged = .false.
        do iteration = 1, max_iterations
            ! Xb = (A + sigma B)^-1 B X, and B Xb.
            xb = y
            call shifted%solve(xb, error)
            if (allocated(error)) return
            do j = 1, p
                call bs%matvec(xb(:, j), yb(:, j))
            end do
            ! Residuals of the previous Ritz pairs (B-normalised x, y = B x).
            if (iteration > 1) then
                do j = 1, n_wanted
                    r = xb(:, j) - mu(j)*x(:, j)
                    mr = yb(:, j) - mu(j)*y(:, j)
                    ! Without its components along the other Ritz vectors (see the module description).
                    c = matmul(transpose(y), r)
                    c(j) = 0.0_wp
                    r = r - matmul(x, c)
                    mr = mr - matmul(y, c)
                    residual(j) = sqrt(max(dot_product(r, mr), 0.0_wp))/mu(j)
                end do
                converged = all(residual <= residual_tolerance .and. &
                                (residual <= residual_floor .or. residual > 0.5_wp*previous))
                previous = residual
            end if
            call orthonormalise(xb, y, yb, error)
            if (allocated(error)) return
            ! Rayleigh-Ritz: Xb^T B Xb q = mu Xb^T (A + sigma B) Xb q, with (A + sigma B) Xb = B X.
            khat = matmul(transpose(xb), y)
            mhat = matmul(transpose(xb), yb)
            khat = 0.5_wp*(khat + transpose(khat))
            mhat = 0.5_wp*(mhat + transpose(mhat))
            call dense_generalized_eigen(mhat, khat, mu_new, q, error)
            if (allocated(error)) then
                error%message = 'generalized eigenproblem: the subspace iteration lost its rank ('// &
                                error%message//')'
                return
            end if
            ! Largest mu (smallest lambda) first; q^T khat q = 1, so q^T mhat q = mu.
            mu_new = mu_new(p:1:-1)
            q = q(:, p:1:-1)
            if (.not. all(mu_new > 0)) then
                call make_error(error, 'generalized eigenproblem: the subspace iteration lost its rank '// &
                                '(a Ritz value is not positive)')
                return
            end if
            do k = 1, p
                q(:, k) = q(:, k)/sqrt(mu_new(k))
            end do
            x = matmul(xb, q)
            y = matmul(yb, q)
            mu = mu_new
            if (converged) exit
        end do
        if (present(iterations)) iterations = min(iteration, max_iterations)
        if (.not. converged) then
            write (buf, '(a,i0,a)') 'generalized eigenproblem: the subspace iteration did not converge in ', &
                max_iterations, ' iterations'
            call make_error(error, trim(buf))
            return
        end if
        ! Exact B-normalisation, the sign convention, then the units of the caller.
        do j = 1, n_wanted
            call bs%matvec(x(:, j), mr)
            x(:, j) = x(:, j)/sqrt(dot_product(x(:, j), mr))
            k = maxloc(abs(x(:, j)), 1)
            if (x(k, j) < 0) x(:, j) = -x(:, j)
        end do
        lambda = scale(1.0_wp/mu(1:n_wanted) - sigma, ea - eb)
        vectors = scale(x(:, 1:n_wanted), -eb/2)
        if (present(shift)) shift = scale(sigma, ea - eb)
    end subroutine lowest_band_eigen

    !> Factor A + sigma B: sigma = 0 if A factors, otherwise the smallest of 1e-10, 1e-8, ...,
    !> 1e-4 times max_i A_ii/B_ii that does (see the module description).
    subroutine choose_shift(a, b, shifted, sigma, error)
        type(band_spd_t), intent(in) :: a, b
        type(band_spd_t), intent(out) :: shifted
        real(wp), intent(out) :: sigma
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: da(:), db(:)
        real(wp) :: unit
        integer :: attempt
        sigma = 0.0_wp
        shifted = a
        call shifted%factor(error)
        if (.not. allocated(error)) return
        allocate (da(a%n), db(b%n))
        call a%diagonal(da)
        call b%diagonal(db)
        unit = maxval(da/db)
        do attempt = 0, 3
            deallocate (error)
            sigma = 1.0e-10_wp*100.0_wp**attempt*unit
            shifted = a
            call shifted%add_scaled(b, sigma)
            call shifted%factor(error)
            if (.not. allocated(error)) return
        end do
        error%message = 'generalized eigenproblem: A + sigma B could not be factored for any shift '// &
                        'up to 1e-4 max A_ii/B_ii ('//error%message//')'
    end subroutine choose_shift

    !> Make the columns of xb B-orthonormal (classical Gram-Schmidt, twice: "twice is enough"),
    !> applying the same column operations to y and yb (which are linear images of xb).
    subroutine orthonormalise(xb, y, yb, error)
        real(wp), intent(inout) :: xb(:, :), y(:, :), yb(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: c(:)
        real(wp) :: norm, before
        integer :: j, pass
        do j = 1, size(xb, 2)
            before = sqrt(max(dot_product(xb(:, j), yb(:, j)), 0.0_wp))
            do pass = 1, 2
                if (j == 1) exit
                c = matmul(transpose(yb(:, 1:j - 1)), xb(:, j))
                xb(:, j) = xb(:, j) - matmul(xb(:, 1:j - 1), c)
                y(:, j) = y(:, j) - matmul(y(:, 1:j - 1), c)
                yb(:, j) = yb(:, j) - matmul(yb(:, 1:j - 1), c)
            end do
            norm = sqrt(max(dot_product(xb(:, j), yb(:, j)), 0.0_wp))
            ! A column that Gram-Schmidt reduces to rounding was a combination of the others.
            if (.not. (norm > 1.0e3_wp*epsilon(1.0_wp)*before .and. norm <= huge(norm))) then
                call make_error(error, 'generalized eigenproblem: the subspace iteration lost its rank '// &
                                '(a vector of B-norm zero or not finite)')
                return
            end if
            xb(:, j) = xb(:, j)/norm
            y(:, j) = y(:, j)/norm
            yb(:, j) = yb(:, j)/norm
        end do
    end subroutine orthonormalise

    !> Deterministic pseudo-random start vectors, entries in (-1/2, 1/2) (MINSTD generator:
    !> the same vectors on every run and machine, no shared random state).
    pure subroutine start_vectors(x)
        real(wp), intent(out) :: x(:, :)
        integer(i8), parameter :: modulus = 2147483647_i8, multiplier = 48271_i8
        integer(i8) :: state
        integer :: i, j
        state = 20240601_i8
        do j = 1, size(x, 2)
            do i = 1, size(x, 1)
                state = mod(multiplier*state, modulus)
                x(i, j) = real(state, wp)/real(modulus, wp) - 0.5_wp
            end do
        end do
    end subroutine start_vectors
end module core_band_eigen
