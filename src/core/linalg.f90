!> Linear algebra for MULTICOR: the only module that calls LAPACK/BLAS.
!>
!> - `band_spd_t`: symmetric positive-definite band matrix in LAPACK upper band storage
!>   `ab(kd+1, n)` (A(i,j) = ab(kd+1+i-j, j) for j-kd <= i <= j); assembly, band Cholesky
!>   (dpbtrf once, dpbtrs for each right-hand side) and products (dsbmv). The assembled
!>   matrix is kept unfactored next to its factor, so products stay available after `factor`.
!> - `dense_spd_t`: dense symmetric positive-definite matrix, Cholesky (dpotrf/dpotrs).
!> - `band_generalized_eigen`: selected eigenpairs of A x = lambda B x for band A, B (dsbgvx),
!>   eigenvectors B-normalised; `largest_generalized_eigenvalue` for the critical time step.
!> - `dense_generalized_eigen`: all eigenpairs of a small dense A x = lambda B x (dsygv), e.g.
!>   the Rayleigh-Ritz problem of a subspace iteration.
!>
!> - `even_exponent`: the power of 2 that scales a matrix to entries of order 1, exactly.
!> - `symmetrize`: A = factor (A + A^T)/2 in place (no n^2 temporary).
!> - `dot`: the dot product of two contiguous vectors (ddot; vectorised, where a Fortran
!>   loop must add in order).
!>
!> Every LAPACK failure (info /= 0) comes back as an `error_t` with the routine's name and
!> what the value of info means.
module core_linalg
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    implicit none
    private
    public :: band_spd_t, dense_spd_t, band_generalized_eigen, largest_generalized_eigenvalue, dense_generalized_eigen
    public :: dot, symmetrize, even_exponent

    !> Symmetric positive-definite band matrix (upper band storage) and its Cholesky factor.
    type :: band_spd_t
        !> Order of the matrix.
        integer :: n = 0
        !> Number of super-diagonals.
        integer :: kd = 0
        !> Assembled matrix, upper band storage (kd+1, n); never overwritten by `factor`.
        real(wp), allocatable :: ab(:, :)
        !> Cholesky factor U (A = U^T U) in the same storage, valid once `factored`.
        real(wp), allocatable :: fac(:, :)
        !> True after a successful `factor`.
        logical :: factored = .false.
        !> Set when `add`/`set` received an entry outside the band (a programming error,
        !> reported by `factor`).
        logical :: out_of_band = .false.
        !> Equation at which the last `factor` failed (0 if it succeeded).
        integer :: failed_equation = 0
    contains
        !> Allocate an n x n zero matrix with kd super-diagonals.
        procedure :: init => band_init
        !> Set all entries to zero (keeps the shape, forgets the factor).
        procedure :: zero => band_zero
        !> Set entry (i, j).
        procedure :: set => band_set
        !> Add to entry (i, j).
        procedure :: add => band_add
        !> self = self + factor*other (other%kd <= self%kd).
        procedure :: add_scaled => band_add_scaled
        !> Diagonal of the matrix.
        procedure :: diagonal => band_diagonal
        !> Cholesky factorisation (dpbtrf).
        procedure :: factor => band_factor
        procedure, private :: band_solve_vec, band_solve_mat
        !> Solve A x = b in place, one or several right-hand sides (dpbtrs).
        generic :: solve => band_solve_vec, band_solve_mat
        !> y = alpha*A*x + beta*y (dsbmv); alpha = 1, beta = 0 by default.
        procedure :: matvec => band_matvec
    end type band_spd_t

    !> Dense symmetric positive-definite matrix (upper triangle used) and its Cholesky factor.
    type :: dense_spd_t
        !> Order of the matrix.
        integer :: n = 0
        !> The matrix (n, n); only the upper triangle is read by `factor`.
        real(wp), allocatable :: a(:, :)
        !> Cholesky factor U (upper triangle), valid once `factored`.
        real(wp), allocatable :: fac(:, :)
        !> True after a successful `factor`.
        logical :: factored = .false.
    contains
        !> Allocate an n x n zero matrix.
        procedure :: init => dense_init
        !> Add to entry (i, j) (and (j, i), keeping the matrix symmetric).
        procedure :: add => dense_add
        !> Cholesky factorisation (dpotrf).
        procedure :: factor => dense_factor
        !> Estimate of the reciprocal condition number in the 1-norm of the factored matrix
        !> (dlansy, dpocon).
        procedure :: rcond => dense_rcond
        procedure, private :: dense_solve_vec, dense_solve_mat
        !> Solve A x = b in place, one or several right-hand sides (dpotrs).
        generic :: solve => dense_solve_vec, dense_solve_mat
        !> The inverse of the factored matrix, both triangles (dpotri: n^3 flops, against
        !> 2 n^3 for dpotrs on the identity).
        procedure :: inverse => dense_inverse
    end type dense_spd_t

    interface
        function ddot(n, x, incx, y, incy) result(value)
            import :: wp
            integer, intent(in) :: n, incx, incy
            real(wp), intent(in) :: x(*), y(*)
            real(wp) :: value
        end function ddot
        subroutine dpbtrf(uplo, n, kd, ab, ldab, info)
            import :: wp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, kd, ldab
            real(wp), intent(inout) :: ab(ldab, *)
            integer, intent(out) :: info
        end subroutine dpbtrf
        subroutine dpbtrs(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
            import :: wp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, kd, nrhs, ldab, ldb
            real(wp), intent(in) :: ab(ldab, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dpbtrs
        subroutine dsbmv(uplo, n, k, alpha, a, lda, x, incx, beta, y, incy)
            import :: wp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, k, lda, incx, incy
            real(wp), intent(in) :: alpha, beta
            real(wp), intent(in) :: a(lda, *), x(*)
            real(wp), intent(inout) :: y(*)
        end subroutine dsbmv
        subroutine dpotrf(uplo, n, a, lda, info)
            import :: wp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, lda
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: info
        end subroutine dpotrf
        subroutine dpocon(uplo, n, a, lda, anorm, rcond, work, iwork, info)
            import :: wp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, lda
            real(wp), intent(in) :: a(lda, *), anorm
            real(wp), intent(out) :: rcond, work(*)
            integer, intent(out) :: iwork(*), info
        end subroutine dpocon
        function dlansy(norm, uplo, n, a, lda, work) result(value)
            import :: wp
            character(len=1), intent(in) :: norm, uplo
            integer, intent(in) :: n, lda
            real(wp), intent(in) :: a(lda, *)
            real(wp), intent(inout) :: work(*)
            real(wp) :: value
        end function dlansy
        subroutine dpotri(uplo, n, a, lda, info)
            import :: wp
            character, intent(in) :: uplo
            integer, intent(in) :: n, lda
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: info
        end subroutine dpotri
        subroutine dpotrs(uplo, n, nrhs, a, lda, b, ldb, info)
            import :: wp
            character(len=1), intent(in) :: uplo
            integer, intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(in) :: a(lda, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dpotrs
        subroutine dsbgvx(jobz, range, uplo, n, ka, kb, ab, ldab, bb, ldbb, q, ldq, vl, vu, &
                          il, iu, abstol, m, w, z, ldz, work, iwork, ifail, info)
            import :: wp
            character(len=1), intent(in) :: jobz, range, uplo
            integer, intent(in) :: n, ka, kb, ldab, ldbb, ldq, il, iu, ldz
            real(wp), intent(inout) :: ab(ldab, *), bb(ldbb, *)
            real(wp), intent(out) :: q(ldq, *), w(*), z(ldz, *), work(*)
            real(wp), intent(in) :: vl, vu, abstol
            integer, intent(out) :: m, iwork(*), ifail(*), info
        end subroutine dsbgvx
        subroutine dsygv(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, info)
            import :: wp
            character(len=1), intent(in) :: jobz, uplo
            integer, intent(in) :: itype, n, lda, ldb, lwork
            real(wp), intent(inout) :: a(lda, *), b(ldb, *)
            real(wp), intent(out) :: w(*), work(*)
            integer, intent(out) :: info
        end subroutine dsygv
    end interface

contains

    !> x . y (BLAS ddot) of two vectors of the same size. Callers that need the same sum
    !> for any number of threads keep the vectors short (dem_nlgs: at most 3072 entries):
    !> OpenBLAS splits a dot product over its threads only beyond 10 000 entries.
    real(wp) function dot(x, y)
        !> First vector.
        real(wp), intent(in), contiguous :: x(:)
        !> Second vector, of the size of x.
        real(wp), intent(in), contiguous :: y(:)
        dot = ddot(size(x), x, 1, y, 1)
    end function dot

    !> Allocate an n x n zero band matrix with kd super-diagonals.
    pure subroutine band_init(self, n, kd)
        !> The matrix.
        class(band_spd_t), intent(inout) :: self
        !> Order (>= 1).
        integer, intent(in) :: n
        !> Number of super-diagonals (0 <= kd < n; larger values are clipped to n-1).
        integer, intent(in) :: kd
        self%n = n
        self%kd = max(0, min(kd, n - 1))
        if (allocated(self%ab)) deallocate (self%ab)
        if (allocated(self%fac)) deallocate (self%fac)
        allocate (self%ab(self%kd + 1, n), source=0.0_wp)
        self%factored = .false.
        self%out_of_band = .false.
        self%failed_equation = 0
    end subroutine band_init

    !> Set all entries to zero; the factor becomes invalid.
    pure subroutine band_zero(self)
        !> The matrix.
        class(band_spd_t), intent(inout) :: self
        self%ab = 0.0_wp
        self%factored = .false.
        self%out_of_band = .false.
    end subroutine band_zero

    !> Set entry (i, j). Only the upper triangle is stored: entries with i > j are ignored
    !> (the matrix is symmetric), so a full symmetric element matrix can be set entry by entry.
    pure subroutine band_set(self, i, j, value)
        !> The matrix.
        class(band_spd_t), intent(inout) :: self
        !> Row and column (1..n).
        integer, intent(in) :: i, j
        !> Value of A(i, j) = A(j, i).
        real(wp), intent(in) :: value
        if (i > j) return
        if (j - i > self%kd) then
            self%out_of_band = .true.
            return
        end if
        self%ab(self%kd + 1 + i - j, j) = value
        self%factored = .false.
    end subroutine band_set

    !> Add to entry (i, j). Entries with i > j are ignored (symmetric storage, see `set`).
    pure subroutine band_add(self, i, j, value)
        !> The matrix.
        class(band_spd_t), intent(inout) :: self
        !> Row and column (1..n).
        integer, intent(in) :: i, j
        !> Value added to A(i, j) = A(j, i).
        real(wp), intent(in) :: value
        if (i > j) return
        if (j - i > self%kd) then
            self%out_of_band = .true.
            return
        end if
        self%ab(self%kd + 1 + i - j, j) = self%ab(self%kd + 1 + i - j, j) + value
        self%factored = .false.
    end subroutine band_add

    !> self = self + factor*other. Both have the same order and other%kd <= self%kd.
    pure subroutine band_add_scaled(self, other, factor)
        !> The matrix to add to.
        class(band_spd_t), intent(inout) :: self
        !> The matrix added.
        type(band_spd_t), intent(in) :: other
        !> Scale of `other`.
        real(wp), intent(in) :: factor
        integer :: shift
        if (other%kd > self%kd .or. other%n /= self%n) then
            self%out_of_band = .true.
            return
        end if
        shift = self%kd - other%kd
        self%ab(shift + 1:, :) = self%ab(shift + 1:, :) + factor*other%ab
        self%factored = .false.
    end subroutine band_add_scaled

    !> Diagonal of the (unfactored) matrix.
    pure subroutine band_diagonal(self, d)
        !> The matrix.
        class(band_spd_t), intent(in) :: self
        !> A(i, i), size n.
        real(wp), intent(out) :: d(:)
        d = self%ab(self%kd + 1, :)
    end subroutine band_diagonal

    !> Cholesky factorisation A = U^T U (dpbtrf). Fails when A is not (numerically) positive
    !> definite; `failed_equation` then tells which equation, for the caller's message.
    subroutine band_factor(self, error)
        !> The matrix; its factor is stored in `fac`.
        class(band_spd_t), intent(inout) :: self
        !> Set when the matrix is not positive definite or the band was exceeded.
        type(error_t), allocatable, intent(out) :: error
        integer :: info, j
        real(wp) :: tol
        character(len=160) :: buf
        self%factored = .false.
        self%failed_equation = 0
        if (self%out_of_band) then
            call make_internal_error(error, 'band matrix', 'an entry was added outside the band '// &
                                     '(bandwidth computed too small)')
            return
        end if
        self%fac = self%ab
        call dpbtrf('U', self%n, self%kd, self%fac, self%kd + 1, info)
        if (info < 0) then
            write (buf, '(a,i0,a)') 'band Cholesky (dpbtrf): argument ', -info, ' is invalid'
            call make_error(error, trim(buf))
            return
        end if
        ! A pivot d_j = U(j,j)^2 below n*eps*A(j,j) is at the rounding level of the
        ! elimination: the j-th equation is a combination of the previous ones up to rounding
        ! (exactly singular matrices give ratios ~1e-16..1e-15 instead of failing in dpbtrf).
        tol = self%n*epsilon(1.0_wp)
        if (info == 0) then
            do j = 1, self%n
                if (self%fac(self%kd + 1, j)**2 <= tol*self%ab(self%kd + 1, j)) then
                    info = j
                    exit
                end if
            end do
        end if
        if (info > 0) then
            self%failed_equation = info
            write (buf, '(a,i0,a)') 'band Cholesky (dpbtrf): matrix is singular or not '// &
                'positive definite at equation ', info, ' of the factorisation'
            call make_error(error, trim(buf))
            return
        end if
        self%factored = .true.
    end subroutine band_factor

    !> Solve A x = b for one right-hand side; b is overwritten by x.
    subroutine band_solve_vec(self, b, error)
        !> The factored matrix.
        class(band_spd_t), intent(in) :: self
        !> Right-hand side on entry, solution on exit (size n).
        real(wp), contiguous, intent(inout) :: b(:)
        !> Set when the matrix is not factored or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        integer :: info
        call check_solve(self%factored, self%n, size(b), 'band', error)
        if (allocated(error)) return
        call dpbtrs('U', self%n, self%kd, 1, self%fac, self%kd + 1, b, self%n, info)
        if (info /= 0) call make_internal_error(error, 'band Cholesky solve', 'dpbtrs: invalid argument')
    end subroutine band_solve_vec

    !> Solve A X = B for several right-hand sides (columns of b); b is overwritten by X.
    subroutine band_solve_mat(self, b, error)
        !> The factored matrix.
        class(band_spd_t), intent(in) :: self
        !> Right-hand sides on entry, solutions on exit (n, nrhs).
        real(wp), contiguous, intent(inout) :: b(:, :)
        !> Set when the matrix is not factored or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        integer :: info
        call check_solve(self%factored, self%n, size(b, 1), 'band', error)
        if (allocated(error)) return
        call dpbtrs('U', self%n, self%kd, size(b, 2), self%fac, self%kd + 1, b, self%n, info)
        if (info /= 0) call make_internal_error(error, 'band Cholesky solve', 'dpbtrs: invalid argument')
    end subroutine band_solve_mat

    !> y = alpha*A*x + beta*y with the unfactored matrix (dsbmv).
    subroutine band_matvec(self, x, y, alpha, beta)
        !> The matrix.
        class(band_spd_t), intent(in) :: self
        !> Vector (size n).
        real(wp), contiguous, intent(in) :: x(:)
        !> Result (size n); read only when beta /= 0.
        real(wp), contiguous, intent(inout) :: y(:)
        !> Scale of A*x (default 1).
        real(wp), intent(in), optional :: alpha
        !> Scale of the incoming y (default 0: y is overwritten).
        real(wp), intent(in), optional :: beta
        real(wp) :: al, be
        al = 1.0_wp
        be = 0.0_wp
        if (present(alpha)) al = alpha
        if (present(beta)) be = beta
        ! BLAS need not read y when beta = 0; clear it so garbage (or NaN) never propagates.
        if (be == 0.0_wp) y = 0.0_wp
        call dsbmv('U', self%n, self%kd, al, self%ab, self%kd + 1, x, 1, be, y, 1)
    end subroutine band_matvec

    !> Common checks before a solve.
    subroutine check_solve(factored, n, nb, what, error)
        logical, intent(in) :: factored
        integer, intent(in) :: n, nb
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        if (.not. factored) then
            call make_error(error, what//' Cholesky solve: the matrix is not factored '// &
                            '(call factor first, and again after changing entries)')
        else if (nb /= n) then
            call make_internal_error(error, what//' Cholesky solve', 'right-hand side has the wrong size')
        end if
    end subroutine check_solve

    !> Allocate an n x n zero dense matrix.
    pure subroutine dense_init(self, n)
        !> The matrix.
        class(dense_spd_t), intent(inout) :: self
        !> Order (>= 1).
        integer, intent(in) :: n
        self%n = n
        if (allocated(self%a)) deallocate (self%a)
        if (allocated(self%fac)) deallocate (self%fac)
        allocate (self%a(n, n), source=0.0_wp)
        self%factored = .false.
    end subroutine dense_init

    !> Add to entry (i, j) and, if i /= j, to (j, i).
    pure subroutine dense_add(self, i, j, value)
        !> The matrix.
        class(dense_spd_t), intent(inout) :: self
        !> Row and column (1..n).
        integer, intent(in) :: i, j
        !> Value added.
        real(wp), intent(in) :: value
        self%a(i, j) = self%a(i, j) + value
        if (i /= j) self%a(j, i) = self%a(j, i) + value
        self%factored = .false.
    end subroutine dense_add

    !> Cholesky factorisation A = U^T U (dpotrf).
    subroutine dense_factor(self, error)
        !> The matrix; its factor is stored in `fac`.
        class(dense_spd_t), intent(inout) :: self
        !> Set when the matrix is not positive definite.
        type(error_t), allocatable, intent(out) :: error
        integer :: info
        character(len=160) :: buf
        self%factored = .false.
        self%fac = self%a
        call dpotrf('U', self%n, self%fac, self%n, info)
        if (info < 0) then
            write (buf, '(a,i0,a)') 'dense Cholesky (dpotrf): argument ', -info, ' is invalid'
            call make_error(error, trim(buf))
        else if (info > 0) then
            write (buf, '(a,i0,a)') 'dense Cholesky (dpotrf): matrix is not positive '// &
                'definite (leading minor of order ', info, ')'
            call make_error(error, trim(buf))
        else
            self%factored = .true.
        end if
    end subroutine dense_factor

    !> Reciprocal condition number 1/(|A|_1 |A^-1|_1), estimated by LAPACK (dpocon) from the
    !> Cholesky factor; 0 when the matrix is not factored.
    real(wp) function dense_rcond(self) result(rcond)
        !> The factored matrix.
        class(dense_spd_t), intent(in) :: self
        real(wp), allocatable :: work(:)
        integer, allocatable :: iwork(:)
        real(wp) :: anorm
        integer :: info
        rcond = 0.0_wp
        if (.not. self%factored .or. self%n == 0) return
        allocate (work(3*self%n), iwork(self%n))
        anorm = dlansy('1', 'U', self%n, self%a, self%n, work)
        call dpocon('U', self%n, self%fac, self%n, anorm, rcond, work, iwork, info)
        if (info /= 0) rcond = 0.0_wp
    end function dense_rcond

    !> Solve A x = b for one right-hand side; b is overwritten by x.
    subroutine dense_solve_vec(self, b, error)
        !> The factored matrix.
        class(dense_spd_t), intent(in) :: self
        !> Right-hand side on entry, solution on exit (size n).
        real(wp), contiguous, intent(inout) :: b(:)
        !> Set when the matrix is not factored or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        integer :: info
        call check_solve(self%factored, self%n, size(b), 'dense', error)
        if (allocated(error)) return
        call dpotrs('U', self%n, 1, self%fac, self%n, b, self%n, info)
        if (info /= 0) call make_internal_error(error, 'dense Cholesky solve', 'dpotrs: invalid argument')
    end subroutine dense_solve_vec

    !> Solve A X = B for several right-hand sides (columns of b); b is overwritten by X.
    subroutine dense_solve_mat(self, b, error)
        !> The factored matrix.
        class(dense_spd_t), intent(in) :: self
        !> Right-hand sides on entry, solutions on exit (n, nrhs).
        real(wp), contiguous, intent(inout) :: b(:, :)
        !> Set when the matrix is not factored or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        integer :: info
        call check_solve(self%factored, self%n, size(b, 1), 'dense', error)
        if (allocated(error)) return
        call dpotrs('U', self%n, size(b, 2), self%fac, self%n, b, self%n, info)
        if (info /= 0) call make_internal_error(error, 'dense Cholesky solve', 'dpotrs: invalid argument')
    end subroutine dense_solve_mat

    !> A = factor (A + A^T)/2 in place, factor = 1 by default; each pair of entries is computed
    !> once, so the result is exactly symmetric (the same values as the array expression).
    pure subroutine symmetrize(a, factor)
        !> Square matrix.
        real(wp), intent(inout) :: a(:, :)
        !> Scale applied with the average.
        real(wp), intent(in), optional :: factor
        real(wp) :: c, v
        integer :: i, j
        c = 0.5_wp
        if (present(factor)) c = factor*0.5_wp
        do j = 1, size(a, 2)
            do i = 1, j
                v = c*(a(i, j) + a(j, i))
                a(i, j) = v
                a(j, i) = v
            end do
        end do
    end subroutine symmetrize

    !> B = A^-1 from the Cholesky factor (dpotri), the lower triangle copied from the upper one
    !> (B is exactly symmetric).
    subroutine dense_inverse(self, b, error)
        !> The factored matrix.
        class(dense_spd_t), intent(in) :: self
        !> The inverse (n, n).
        real(wp), allocatable, intent(out) :: b(:, :)
        !> Set when the matrix is not factored or its factor is singular.
        type(error_t), allocatable, intent(out) :: error
        integer :: info, j
        character(len=160) :: buf
        call check_solve(self%factored, self%n, self%n, 'dense', error)
        if (allocated(error)) return
        b = self%fac
        call dpotri('U', self%n, b, self%n, info)
        if (info < 0) then
            call make_internal_error(error, 'dense Cholesky inverse', 'dpotri: invalid argument')
            return
        else if (info > 0) then
            write (buf, '(a,i0,a)') 'dense Cholesky inverse (dpotri): the factor is singular (diagonal entry ', &
                info, ' is zero)'
            call make_error(error, trim(buf))
            return
        end if
        do j = 1, self%n - 1
            b(j + 1:, j) = b(j, j + 1:)
        end do
    end subroutine dense_inverse

    !> Eigenvalues il..iu (ascending) of A x = lambda B x, A symmetric and B symmetric
    !> positive definite, both band (dsbgvx). Eigenvectors, if asked, satisfy X^T B X = I.
    subroutine band_generalized_eigen(a, b, il, iu, lambda, error, vectors)
        !> Matrix A (e.g. stiffness).
        type(band_spd_t), intent(in) :: a
        !> Matrix B (e.g. mass), same order, positive definite.
        type(band_spd_t), intent(in) :: b
        !> Indices of the first and last eigenvalue wanted (1 <= il <= iu <= n).
        integer, intent(in) :: il, iu
        !> Eigenvalues il..iu, ascending.
        real(wp), allocatable, intent(out) :: lambda(:)
        !> Set on invalid input or LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        !> Eigenvectors (n, iu-il+1), B-normalised; computed only if present.
        real(wp), allocatable, intent(out), optional :: vectors(:, :)
        real(wp), allocatable :: ab(:, :), bb(:, :), q(:, :), w(:), z(:, :), work(:)
        integer, allocatable :: iwork(:), ifail(:)
        integer :: n, ka, m, nv, info, ea, eb
        character(len=1) :: jobz
        n = a%n
        if (b%n /= n .or. il < 1 .or. iu > n .or. il > iu) then
            call make_internal_error(error, 'generalized eigenproblem', 'invalid sizes or index range')
            return
        end if
        ! dsbgvx needs ka >= kb: widen A's storage when B is wider.
        ka = max(a%kd, b%kd)
        allocate (ab(ka + 1, n), source=0.0_wp)
        ! Both matrices scaled to entries of order 1 by even powers of 2 (exact, square roots
        ! included): dsbgvx's bisection squares the entries of the reduced matrix, which
        ! overflows from about 1e154 on (a Young's modulus of 1e300 or a density of 1e-300
        ! returned fewer eigenvalues than asked, with info = 0). lambda = 2^(ea - eb) mu.
        ea = even_exponent(a%ab)
        eb = even_exponent(b%ab)
        ab(ka - a%kd + 1:, :) = scale(a%ab, -ea)
        bb = scale(b%ab, -eb)
        jobz = 'N'
        nv = 1
        if (present(vectors)) then
            jobz = 'V'
            nv = n
        end if
        ! q holds the reduction matrix (n, n) only when vectors are wanted.
        allocate (q(nv, nv), w(n), z(n, merge(iu - il + 1, 1, present(vectors))), work(7*n))
        allocate (iwork(5*n), ifail(n))
        ! abstol = 2*safe minimum: most accurate eigenvalues (LAPACK's recommendation).
        call dsbgvx(jobz, 'I', 'U', n, ka, b%kd, ab, ka + 1, bb, b%kd + 1, q, nv, 0.0_wp, &
                    0.0_wp, il, iu, 2*tiny(1.0_wp), m, w, z, n, work, iwork, ifail, info)
        call eigen_info_error(info, n, error)
        if (allocated(error)) return
        ! Beyond the range of real(wp) the eigenvalues come out infinite: the caller checks.
        lambda = scale(w(1:m), ea - eb)
        ! z^T (B 2^-eb) z = 1: the B-normalised vectors are z 2^(-eb/2).
        if (present(vectors)) vectors = scale(z(:, 1:m), -eb/2)
    end subroutine band_generalized_eigen

    !> Even exponent e such that the largest |entry| of x times 2^-e lies in [1/2, 2) (0 for a
    !> zero or non-finite matrix): scaling by 2^-e is exact, and so is the square root of it.
    pure integer function even_exponent(x) result(e)
        !> The entries (e.g. a band matrix's storage).
        real(wp), intent(in) :: x(:, :)
        real(wp) :: big
        e = 0
        big = maxval(abs(x))
        if (.not. (big > 0.0_wp .and. big <= huge(big))) return
        e = 2*floor(0.5_wp*real(exponent(big), wp))
    end function even_exponent

    !> All eigenpairs of A x = lambda B x, A symmetric and B symmetric positive definite, both
    !> dense and small (dsygv: Cholesky of B, then the standard problem; n^3 flops). Only the
    !> upper triangles are read. Eigenvalues ascending, eigenvectors with X^T B X = I.
    subroutine dense_generalized_eigen(a, b, lambda, vectors, error)
        !> Matrix A (n, n).
        real(wp), intent(in) :: a(:, :)
        !> Matrix B (n, n), positive definite.
        real(wp), intent(in) :: b(:, :)
        !> The n eigenvalues, ascending.
        real(wp), allocatable, intent(out) :: lambda(:)
        !> The eigenvectors (n, n), B-normalised, in the order of lambda.
        real(wp), allocatable, intent(out) :: vectors(:, :)
        !> Set on invalid sizes or LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: bb(:, :), work(:)
        real(wp) :: query(1)
        integer :: n, info
        character(len=160) :: buf
        n = size(a, 1)
        if (size(a, 2) /= n .or. any(shape(b) /= [n, n]) .or. n < 1) then
            call make_internal_error(error, 'dense generalized eigenproblem', 'matrices of different or invalid sizes')
            return
        end if
        vectors = a
        bb = b
        allocate (lambda(n))
        call dsygv(1, 'V', 'U', n, vectors, n, bb, n, lambda, query, -1, info)
        allocate (work(max(1, int(query(1)))))
        call dsygv(1, 'V', 'U', n, vectors, n, bb, n, lambda, work, size(work), info)
        if (info == 0) return
        if (info < 0) then
            write (buf, '(a,i0,a)') 'dense generalized eigenproblem (dsygv): argument ', -info, ' is invalid'
        else if (info <= n) then
            write (buf, '(a,i0,a)') 'dense generalized eigenproblem (dsygv): ', info, &
                ' off-diagonal elements did not converge to zero'
        else
            write (buf, '(a,i0,a)') 'dense generalized eigenproblem (dsygv): the second matrix is not '// &
                'positive definite (leading minor of order ', info - n, ')'
        end if
        call make_error(error, trim(buf))
    end subroutine dense_generalized_eigen

    !> Largest eigenvalue of A x = lambda B x (A symmetric, B symmetric positive definite,
    !> both band), e.g. omega_max^2 of K x = omega^2 M x for the critical time step.
    subroutine largest_generalized_eigenvalue(a, b, lambda_max, error)
        !> Matrix A.
        type(band_spd_t), intent(in) :: a
        !> Matrix B, positive definite.
        type(band_spd_t), intent(in) :: b
        !> The largest eigenvalue.
        real(wp), intent(out) :: lambda_max
        !> Set on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: lambda(:)
        lambda_max = 0.0_wp
        call band_generalized_eigen(a, b, a%n, a%n, lambda, error)
        if (allocated(error)) return
        lambda_max = lambda(1)
    end subroutine largest_generalized_eigenvalue

    !> Turn the info of dsbgvx into an error.
    subroutine eigen_info_error(info, n, error)
        integer, intent(in) :: info, n
        type(error_t), allocatable, intent(out) :: error
        character(len=200) :: buf
        if (info == 0) return
        if (info < 0) then
            write (buf, '(a,i0,a)') 'generalized eigenproblem (dsbgvx): argument ', -info, &
                ' is invalid'
        else if (info <= n) then
            write (buf, '(i0,a)') info, ' eigenvectors failed to converge (dsbgvx)'
        else
            write (buf, '(a,i0,a)') 'generalized eigenproblem (dsbgvx): the second matrix '// &
                '(mass) is not positive definite (equation ', info - n, ')'
        end if
        call make_error(error, trim(buf))
    end subroutine eigen_info_error
end module core_linalg
