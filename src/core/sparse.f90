!> Sparse symmetric matrices and their direct solution with SuiteSparse CHOLMOD: the only
!> module that calls CHOLMOD (through the C layer `sparse_c.c`, which keeps CHOLMOD's structs
!> on the C side).
!>
!> - `sparse_matrix_t`: a symmetric n x n matrix assembled from triplets (i, j, value),
!>   duplicates summed, either triangle accepted; `finalize` compresses it (CHOLMOD's
!>   triplet-to-sparse conversion) into compressed sparse columns holding the **lower**
!>   triangle. The pattern is then fixed: `zero_values` and `add` again, or `position` once
!>   and `values(k)` in the loop, give new values for a new factorisation that reuses the
!>   symbolic analysis.
!> - `sparse_solver_t`: `analyse` (fill-reducing ordering and symbolic factorisation, once per
!>   pattern), `factor` (numerical factorisation, each time the values change), `solve` (one
!>   or several right-hand sides), `stats` (nonzeros and flops of the factor, ordering used).
!>   `delete_rows` modifies the factor in place so that it solves the matrix with some rows
!>   and columns replaced by those of the identity (CHOLMOD's row deletion, without a new
!>   analysis or factorisation; the factor becomes simplicial L D L^T).
!>   Two kinds: `sparse_cholesky`, A = L L^T for symmetric positive-definite matrices
!>   (supernodal or simplicial as CHOLMOD judges faster; a pivot <= 0 is an error naming the
!>   column), and `sparse_ldlt`, A = L D L^T without pivoting (simplicial), for
!>   symmetric quasi-definite matrices such as the regularised saddle point
!>   [M, H^T; H, -eps I] (a zero pivot is an error).
!>
!> CHOLMOD's memory (settings, workspace, factor) lives in the solver object and is freed by
!> `destroy` or when the object is finalised; assigning a solver copies its factor. Every
!> failure comes back as an `error_t`. Choice of the library, kinds and orderings:
!> doc/decisions.md.
module core_sparse
    use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_int, c_int64_t, c_double
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_internal_error
    implicit none
    private
    public :: sparse_matrix_t, sparse_solver_t, sparse_stats_t
    public :: sparse_cholesky, sparse_ldlt
    public :: sparse_order_auto, sparse_order_amd, sparse_order_metis, sparse_order_natural

    !> Factorisation A = L L^T of a symmetric positive-definite matrix.
    integer, parameter :: sparse_cholesky = 1
    !> Factorisation A = L D L^T without pivoting of a symmetric quasi-definite (or
    !> positive-definite) matrix; D may have negative entries.
    integer, parameter :: sparse_ldlt = 2
    !> Ordering chosen by CHOLMOD: AMD, and METIS as well when AMD gives much fill-in.
    integer, parameter :: sparse_order_auto = 0
    !> Approximate minimum degree ordering.
    integer, parameter :: sparse_order_amd = 1
    !> METIS nested dissection ordering.
    integer, parameter :: sparse_order_metis = 2
    !> No reordering (the factor of a banded matrix stays in its band).
    integer, parameter :: sparse_order_natural = 3

    ! CHOLMOD status codes (cholmod_core.h) and the C layer's own.
    integer(c_int), parameter :: cholmod_ok = 0, cholmod_not_posdef = 1
    integer(c_int), parameter :: cholmod_not_installed = -1, cholmod_out_of_memory = -2, &
                                 cholmod_too_large = -3, cholmod_invalid = -4, mc_no_handle = -100

    !> Symmetric sparse matrix: triplets until `finalize`, then compressed sparse columns of
    !> the lower triangle with the 0-based 64-bit offsets and row indices CHOLMOD reads.
    type :: sparse_matrix_t
        private
        !> Order of the matrix.
        integer, public :: n = 0
        !> True once `finalize` has compressed the triplets (the pattern is fixed).
        logical, public :: finalized = .false.
        !> Column starts (size n+1, 0-based offsets into `rowind`/`values`): the entries of
        !> column j are values(colptr(j)+1 : colptr(j+1)). Read only.
        integer(i8), allocatable, public :: colptr(:)
        !> 0-based row index of each stored entry (row >= column), sorted within each column.
        !> Read only.
        integer(i8), allocatable, public :: rowind(:)
        !> Value of each stored entry; may be changed in place (see `position`).
        real(wp), allocatable, public :: values(:)
        ! Triplets (0-based row, 0-based column, value) and their number, before `finalize`.
        integer(i8) :: ntriplets = 0
        integer(i8), allocatable :: ti(:), tj(:)
        real(wp), allocatable :: tv(:)
        ! First (i, j) given to `add` outside 1..n, or outside the fixed pattern after
        ! `finalize` ((0, 0) when none): reported by `finalize` and `factor`.
        integer :: bad_entry(2) = 0
    contains
        !> Start an empty n x n matrix with room for nnz_hint triplets.
        procedure :: init => matrix_init
        !> Add a value to A(i, j) = A(j, i).
        procedure :: add => matrix_add
        !> Add a full symmetric block (element matrix) at the given rows and columns.
        procedure :: add_block => matrix_add_block
        !> Compress the triplets (duplicates summed): the pattern is fixed from then on.
        procedure :: finalize => matrix_finalize
        !> Number of stored entries (lower triangle with the diagonal).
        procedure :: nnz => matrix_nnz
        !> Index k of A(i, j) in `values` (0 when outside the pattern).
        procedure :: position => matrix_position
        !> Set every stored value to zero (pattern kept), before adding new values.
        procedure :: zero_values => matrix_zero_values
        procedure, private :: matrix_matvec_vec, matrix_matvec_mat
        !> y = alpha*A*x + beta*y for one or several vectors (cholmod_sdmult).
        generic :: matvec => matrix_matvec_vec, matrix_matvec_mat
    end type sparse_matrix_t

    !> Figures of a solver's last analysis and factorisation.
    type :: sparse_stats_t
        !> Order of the matrix.
        integer :: n = 0
        !> Stored entries of the matrix (lower triangle with the diagonal).
        integer(i8) :: nnz_matrix = 0
        !> Nonzeros of the factor L (with its diagonal), from the symbolic analysis.
        real(wp) :: nnz_factor = 0.0_wp
        !> Floating-point operations of one numerical factorisation, from the analysis.
        real(wp) :: flops = 0.0_wp
        !> Fill-reducing ordering used: 'natural', 'amd', 'metis', 'nesdis', 'colamd' or
        !> 'given' ('none' before `analyse`).
        character(len=:), allocatable :: ordering
        !> True for a supernodal factor (dense blocks, BLAS 3), false for a simplicial one.
        logical :: supernodal = .false.
        !> True for L L^T, false for L D L^T.
        logical :: ll = .false.
        !> Number of negative entries of D (L D L^T factors; 0 for L L^T): the number of
        !> negative eigenvalues of A (Sylvester's law of inertia).
        integer(i8) :: negative_pivots = 0
        !> CHOLMOD's rough reciprocal condition estimate from the diagonal of the factor
        !> ((min/max L(j,j))^2, or min/max |D(j,j)|); 0 when not factored.
        real(wp) :: rcond = 0.0_wp
        !> Peak memory used by CHOLMOD for this solver, bytes.
        real(wp) :: memory_peak = 0.0_wp
    end type sparse_stats_t

    !> Sparse direct solver (CHOLMOD) for a symmetric matrix: symbolic analysis once per
    !> pattern, numerical factorisation once per set of values, then solves.
    type :: sparse_solver_t
        private
        ! CHOLMOD's settings, workspace and factor (C layer), or null.
        type(c_ptr) :: handle = c_null_ptr
        integer :: kind = sparse_cholesky
        integer :: ordering = sparse_order_auto
        ! Order, number of entries and a checksum of the analysed pattern.
        integer :: n = 0
        integer(i8) :: nnz = 0
        integer(i8) :: pattern_sum = 0
        logical :: analysed = .false.
        logical :: factored = .false.
        !> Column (1-based, original numbering) where the last `factor` met a pivot <= 0
        !> (`sparse_cholesky`) or = 0 (`sparse_ldlt`); 0 if it succeeded.
        integer, public :: failed_column = 0
    contains
        !> Symbolic analysis of a finalized matrix (ordering, pattern of L).
        procedure :: analyse => solver_analyse
        !> Numerical factorisation of a matrix with the analysed pattern.
        procedure :: factor => solver_factor
        procedure, private :: solver_solve_vec, solver_solve_mat
        !> Solve A x = b for one or several right-hand sides.
        generic :: solve => solver_solve_vec, solver_solve_mat
        !> Replace rows and columns of the factored matrix by those of the identity,
        !> modifying the factor.
        procedure :: delete_rows => solver_delete_rows
        !> Figures of the analysis and factorisation.
        procedure :: stats => solver_stats
        !> True after a successful `factor`.
        procedure :: is_factored => solver_is_factored
        !> Free CHOLMOD's memory (the solver can be analysed again afterwards).
        procedure :: destroy => solver_destroy
        procedure, private :: solver_assign
        !> Copy: the target gets its own CHOLMOD object and a copy of the factor.
        generic :: assignment(=) => solver_assign
        final :: solver_final
    end type sparse_solver_t

    interface
        function mc_sparse_create(kind, ordering) bind(c, name='mc_sparse_create') result(handle)
            import :: c_int, c_ptr
            integer(c_int), value :: kind, ordering
            type(c_ptr) :: handle
        end function mc_sparse_create
        subroutine mc_sparse_destroy(handle) bind(c, name='mc_sparse_destroy')
            import :: c_ptr
            type(c_ptr), value :: handle
        end subroutine mc_sparse_destroy
        function mc_sparse_copy(handle) bind(c, name='mc_sparse_copy') result(copy)
            import :: c_ptr
            type(c_ptr), value :: handle
            type(c_ptr) :: copy
        end function mc_sparse_copy
        function mc_sparse_analyse(handle, n, p, i, x) bind(c, name='mc_sparse_analyse') result(status)
            import :: c_ptr, c_int, c_int64_t, c_double
            type(c_ptr), value :: handle
            integer(c_int64_t), value :: n
            integer(c_int64_t), intent(in) :: p(*), i(*)
            real(c_double), intent(in) :: x(*)
            integer(c_int) :: status
        end function mc_sparse_analyse
        function mc_sparse_factor(handle, n, p, i, x, failed_column) &
            bind(c, name='mc_sparse_factor') result(status)
            import :: c_ptr, c_int, c_int64_t, c_double
            type(c_ptr), value :: handle
            integer(c_int64_t), value :: n
            integer(c_int64_t), intent(in) :: p(*), i(*)
            real(c_double), intent(in) :: x(*)
            integer(c_int64_t), intent(out) :: failed_column
            integer(c_int) :: status
        end function mc_sparse_factor
        function mc_sparse_solve(handle, n, nrhs, b, x) bind(c, name='mc_sparse_solve') result(status)
            import :: c_ptr, c_int, c_int64_t, c_double
            type(c_ptr), value :: handle
            integer(c_int64_t), value :: n, nrhs
            real(c_double), intent(in) :: b(*)
            real(c_double), intent(inout) :: x(*)
            integer(c_int) :: status
        end function mc_sparse_solve
        function mc_sparse_delete(handle, nrows, rows) bind(c, name='mc_sparse_delete') result(status)
            import :: c_ptr, c_int, c_int64_t
            type(c_ptr), value :: handle
            integer(c_int64_t), value :: nrows
            integer(c_int64_t), intent(in) :: rows(*)
            integer(c_int) :: status
        end function mc_sparse_delete
        subroutine mc_sparse_info(handle, lnz, flops, ordering, supernodal, is_ll, negative_pivots, &
                                  rcond, memory_peak) bind(c, name='mc_sparse_info')
            import :: c_ptr, c_int, c_int64_t, c_double
            type(c_ptr), value :: handle
            real(c_double), intent(out) :: lnz, flops, rcond, memory_peak
            integer(c_int), intent(out) :: ordering, supernodal, is_ll
            integer(c_int64_t), intent(out) :: negative_pivots
        end subroutine mc_sparse_info
        function mc_sparse_compress(n, nt, ti, tj, tv, nnz, status) bind(c, name='mc_sparse_compress') &
            result(handle)
            import :: c_ptr, c_int, c_int64_t, c_double
            integer(c_int64_t), value :: n, nt
            integer(c_int64_t), intent(in) :: ti(*), tj(*)
            real(c_double), intent(in) :: tv(*)
            integer(c_int64_t), intent(out) :: nnz
            integer(c_int), intent(out) :: status
            type(c_ptr) :: handle
        end function mc_sparse_compress
        subroutine mc_sparse_compress_take(handle, p, i, x) bind(c, name='mc_sparse_compress_take')
            import :: c_ptr, c_int64_t, c_double
            type(c_ptr), value :: handle
            integer(c_int64_t), intent(out) :: p(*), i(*)
            real(c_double), intent(out) :: x(*)
        end subroutine mc_sparse_compress_take
        function mc_sparse_matvec(n, p, i, x, ncol, xin, yout, alpha, beta) &
            bind(c, name='mc_sparse_matvec') result(status)
            import :: c_int, c_int64_t, c_double
            integer(c_int64_t), value :: n, ncol
            integer(c_int64_t), intent(in) :: p(*), i(*)
            real(c_double), intent(in) :: x(*), xin(*)
            real(c_double), intent(inout) :: yout(*)
            real(c_double), value :: alpha, beta
            integer(c_int) :: status
        end function mc_sparse_matvec
    end interface

contains

    !> Start an empty symmetric n x n matrix (forgets any previous pattern).
    pure subroutine matrix_init(self, n, nnz_hint)
        !> The matrix.
        class(sparse_matrix_t), intent(inout) :: self
        !> Order (>= 1).
        integer, intent(in) :: n
        !> Expected number of `add` calls (storage grows beyond it when needed).
        integer(i8), intent(in), optional :: nnz_hint
        integer(i8) :: cap
        cap = 4*int(max(n, 1), i8)
        if (present(nnz_hint)) cap = max(nnz_hint, 1_i8)
        self%n = n
        self%finalized = .false.
        self%ntriplets = 0
        self%bad_entry = 0
        if (allocated(self%colptr)) deallocate (self%colptr)
        if (allocated(self%rowind)) deallocate (self%rowind)
        if (allocated(self%values)) deallocate (self%values)
        if (allocated(self%ti)) deallocate (self%ti)
        if (allocated(self%tj)) deallocate (self%tj)
        if (allocated(self%tv)) deallocate (self%tv)
        allocate (self%ti(cap), self%tj(cap), self%tv(cap))
    end subroutine matrix_init

    !> Add `value` to the symmetric pair A(i, j) = A(j, i) (once: give each off-diagonal pair
    !> in one triangle only, either one; `add_block` takes full element matrices). Before
    !> `finalize` the entry is appended to the triplets; afterwards it must lie in the pattern.
    !> An index outside 1..n, or an entry outside the fixed pattern, is remembered in
    !> `bad_entry` and reported by `finalize` or `factor`.
    pure subroutine matrix_add(self, i, j, value)
        !> The matrix.
        class(sparse_matrix_t), intent(inout) :: self
        !> Row and column (1..n).
        integer, intent(in) :: i, j
        !> Value added.
        real(wp), intent(in) :: value
        integer(i8) :: k
        if (i < 1 .or. j < 1 .or. i > self%n .or. j > self%n) then
            call remember_bad(self, i, j)
            return
        end if
        if (self%finalized) then
            k = self%position(i, j)
            if (k == 0) then
                call remember_bad(self, i, j)
            else
                self%values(k) = self%values(k) + value
            end if
            return
        end if
        if (self%ntriplets == size(self%ti, kind=i8)) call grow_triplets(self)
        self%ntriplets = self%ntriplets + 1
        self%ti(self%ntriplets) = i - 1
        self%tj(self%ntriplets) = j - 1
        self%tv(self%ntriplets) = value
    end subroutine matrix_add

    !> Add a full symmetric block: A(dofs(a), dofs(b)) += block(a, b). Only the block's lower
    !> triangle (a >= b) is read, so each symmetric pair is added once. Rows with dofs(a) <= 0
    !> (e.g. constrained degrees of freedom) are skipped.
    pure subroutine matrix_add_block(self, dofs, block)
        !> The matrix.
        class(sparse_matrix_t), intent(inout) :: self
        !> Global row/column of each row of the block (<= 0: skipped).
        integer, intent(in) :: dofs(:)
        !> Symmetric block, size(dofs) x size(dofs).
        real(wp), intent(in) :: block(:, :)
        integer :: a, b
        do b = 1, size(dofs)
            if (dofs(b) <= 0) cycle
            do a = b, size(dofs)
                if (dofs(a) <= 0) cycle
                call self%add(dofs(a), dofs(b), block(a, b))
            end do
        end do
    end subroutine matrix_add_block

    !> Compress the triplets into columns of the lower triangle with CHOLMOD's
    !> triplet-to-sparse conversion (duplicates summed, upper-triangle entries transposed,
    !> explicit zeros kept so that the pattern does not depend on the values). Does nothing
    !> when already finalized.
    subroutine matrix_finalize(self, error)
        !> The matrix.
        class(sparse_matrix_t), intent(inout) :: self
        !> Set when an index was outside 1..n, or CHOLMOD fails (memory).
        type(error_t), allocatable, intent(out) :: error
        type(c_ptr) :: handle
        integer(c_int64_t) :: nnz
        integer(c_int) :: status
        if (self%n < 1) then
            call make_internal_error(error, 'sparse matrix', 'finalize called before init')
            return
        end if
        call check_bad_entry(self, error)
        if (allocated(error)) return
        if (self%finalized) return
        handle = mc_sparse_compress(int(self%n, c_int64_t), self%ntriplets, self%ti, self%tj, self%tv, &
                                    nnz, status)
        if (.not. c_associated(handle)) then
            call status_error(status, 'sparse matrix assembly (cholmod_triplet_to_sparse)', error)
            return
        end if
        allocate (self%colptr(self%n + 1), self%rowind(nnz), self%values(nnz))
        call mc_sparse_compress_take(handle, self%colptr, self%rowind, self%values)
        deallocate (self%ti, self%tj, self%tv)
        self%ntriplets = 0
        self%finalized = .true.
    end subroutine matrix_finalize

    !> Number of stored entries (lower triangle with the diagonal); 0 before `finalize`.
    pure function matrix_nnz(self) result(nnz)
        !> The matrix.
        class(sparse_matrix_t), intent(in) :: self
        !> Stored entries.
        integer(i8) :: nnz
        nnz = 0
        if (self%finalized) nnz = self%colptr(self%n + 1)
    end function matrix_nnz

    !> Index k such that values(k) holds A(i, j) = A(j, i), by bisection in the column; 0 when
    !> (i, j) is outside the pattern or the matrix is not finalized. Computing the positions
    !> of an assembly once and adding to values(k) afterwards is the fastest way to refill
    !> the matrix with new values.
    pure function matrix_position(self, i, j) result(k)
        !> The matrix.
        class(sparse_matrix_t), intent(in) :: self
        !> Row and column (1..n), either triangle.
        integer, intent(in) :: i, j
        !> Index into `values`, or 0.
        integer(i8) :: k
        integer(i8) :: row, lo, hi, mid
        integer :: col
        k = 0
        if (.not. self%finalized) return
        if (i < 1 .or. j < 1 .or. i > self%n .or. j > self%n) return
        row = max(i, j) - 1
        col = min(i, j)
        lo = self%colptr(col) + 1
        hi = self%colptr(col + 1)
        do while (lo <= hi)
            mid = (lo + hi)/2
            if (self%rowind(mid) == row) then
                k = mid
                return
            else if (self%rowind(mid) < row) then
                lo = mid + 1
            else
                hi = mid - 1
            end if
        end do
    end function matrix_position

    !> Set every stored value to zero; the pattern (and a solver's analysis of it) is kept.
    pure subroutine matrix_zero_values(self)
        !> The matrix.
        class(sparse_matrix_t), intent(inout) :: self
        if (self%finalized) self%values = 0.0_wp
        self%bad_entry = 0
    end subroutine matrix_zero_values

    !> y = alpha*A*x + beta*y (cholmod_sdmult on the symmetric matrix).
    subroutine matrix_matvec_vec(self, x, y, error, alpha, beta)
        !> The finalized matrix.
        class(sparse_matrix_t), intent(in) :: self
        !> Vector (size n).
        real(wp), contiguous, intent(in) :: x(:)
        !> Result (size n); read only when beta /= 0.
        real(wp), contiguous, intent(inout) :: y(:)
        !> Set when the matrix is not finalized or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        !> Scale of A*x (default 1).
        real(wp), intent(in), optional :: alpha
        !> Scale of the incoming y (default 0: y is overwritten).
        real(wp), intent(in), optional :: beta
        call matvec_common(self, x, y, 1_i8, size(x, kind=i8), size(y, kind=i8), error, alpha, beta)
    end subroutine matrix_matvec_vec

    !> Y = alpha*A*X + beta*Y for the columns of X (cholmod_sdmult).
    subroutine matrix_matvec_mat(self, x, y, error, alpha, beta)
        !> The finalized matrix.
        class(sparse_matrix_t), intent(in) :: self
        !> Vectors (n, m).
        real(wp), contiguous, intent(in) :: x(:, :)
        !> Results (n, m); read only when beta /= 0.
        real(wp), contiguous, intent(inout) :: y(:, :)
        !> Set when the matrix is not finalized or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        !> Scale of A*X (default 1).
        real(wp), intent(in), optional :: alpha
        !> Scale of the incoming Y (default 0: Y is overwritten).
        real(wp), intent(in), optional :: beta
        if (size(x, 2) /= size(y, 2)) then
            call make_error(error, 'sparse matrix product: x and y have different numbers of columns')
            return
        end if
        call matvec_common(self, x, y, size(x, 2, kind=i8), size(x, 1, kind=i8), size(y, 1, kind=i8), &
                           error, alpha, beta)
    end subroutine matrix_matvec_mat

    ! The product for ncol columns of length nx (x) and ny (y), stored contiguously.
    subroutine matvec_common(self, x, y, ncol, nx, ny, error, alpha, beta)
        class(sparse_matrix_t), intent(in) :: self
        real(wp), intent(in) :: x(*)
        real(wp), intent(inout) :: y(*)
        integer(i8), intent(in) :: ncol, nx, ny
        type(error_t), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: alpha, beta
        real(wp) :: al, be
        integer(c_int) :: status
        if (.not. self%finalized) then
            call make_error(error, 'sparse matrix product: the matrix is not finalized')
            return
        end if
        if (nx /= self%n .or. ny /= self%n) then
            call make_internal_error(error, 'sparse matrix product', 'vector of the wrong size')
            return
        end if
        al = 1.0_wp
        be = 0.0_wp
        if (present(alpha)) al = alpha
        if (present(beta)) be = beta
        ! cholmod_sdmult reads y even when beta = 0: clear it so that garbage never propagates.
        if (be == 0.0_wp) y(1:ncol*ny) = 0.0_wp
        status = mc_sparse_matvec(int(self%n, c_int64_t), self%colptr, self%rowind, self%values, ncol, &
                                  x, y, al, be)
        if (status < cholmod_ok) call status_error(status, 'sparse matrix product (cholmod_sdmult)', error)
    end subroutine matvec_common

    !> Symbolic analysis of a finalized matrix: fill-reducing ordering, elimination tree and
    !> pattern of L. Needed once per pattern; `factor` then reuses it for any values.
    subroutine solver_analyse(self, a, error, kind, ordering)
        !> The solver.
        class(sparse_solver_t), intent(inout) :: self
        !> The finalized matrix (its values are not used).
        type(sparse_matrix_t), intent(in) :: a
        !> Set when the matrix is not finalized or CHOLMOD fails.
        type(error_t), allocatable, intent(out) :: error
        !> `sparse_cholesky` (default) or `sparse_ldlt`.
        integer, intent(in), optional :: kind
        !> `sparse_order_auto` (default), `sparse_order_amd`, `sparse_order_metis` or
        !> `sparse_order_natural`.
        integer, intent(in), optional :: ordering
        integer(c_int) :: status
        call solver_destroy(self)
        if (present(kind)) self%kind = kind
        if (present(ordering)) self%ordering = ordering
        if (self%kind /= sparse_cholesky .and. self%kind /= sparse_ldlt) then
            call make_internal_error(error, 'sparse solver', 'kind must be sparse_cholesky or sparse_ldlt')
            return
        end if
        if (self%ordering < sparse_order_auto .or. self%ordering > sparse_order_natural) then
            call make_error(error, 'sparse solver: unknown ordering')
            return
        end if
        if (.not. a%finalized) then
            call make_error(error, 'sparse solver (analyse): the matrix is not finalized')
            return
        end if
        self%handle = mc_sparse_create(int(self%kind, c_int), int(self%ordering, c_int))
        if (.not. c_associated(self%handle)) then
            call make_error(error, 'sparse solver: CHOLMOD could not be started (out of memory)')
            return
        end if
        status = mc_sparse_analyse(self%handle, int(a%n, c_int64_t), a%colptr, a%rowind, a%values)
        if (status < cholmod_ok) then
            call status_error(status, 'sparse symbolic analysis (cholmod_analyze)', error)
            return
        end if
        self%n = a%n
        self%nnz = a%nnz()
        self%pattern_sum = pattern_checksum(a)
        self%analysed = .true.
    end subroutine solver_analyse

    !> Numerical factorisation of `a` with the analysed pattern (analyses first when the
    !> solver has not been analysed). `sparse_cholesky` fails on a pivot <= 0 (matrix not
    !> positive definite), `sparse_ldlt` on a zero pivot (singular matrix); the error names the
    !> column and `failed_column` holds it.
    subroutine solver_factor(self, a, error)
        !> The solver.
        class(sparse_solver_t), intent(inout) :: self
        !> The finalized matrix, with the pattern given to `analyse`.
        type(sparse_matrix_t), intent(in) :: a
        !> Set when the pattern differs from the analysed one, an entry fell outside it, the
        !> matrix is not positive definite (or singular), or CHOLMOD fails.
        type(error_t), allocatable, intent(out) :: error
        integer(c_int64_t) :: failed
        integer(c_int) :: status
        character(len=200) :: buf
        self%factored = .false.
        self%failed_column = 0
        call check_bad_entry(a, error)
        if (allocated(error)) return
        if (.not. self%analysed) then
            call self%analyse(a, error)
            if (allocated(error)) return
        end if
        if (.not. a%finalized) then
            call make_error(error, 'sparse solver (factor): the matrix is not finalized')
            return
        end if
        if (a%n /= self%n .or. a%nnz() /= self%nnz) then
            call make_error(error, 'sparse solver (factor): the matrix does not have the analysed '// &
                            'pattern (call analyse again after changing the pattern)')
            return
        end if
        if (pattern_checksum(a) /= self%pattern_sum) then
            call make_error(error, 'sparse solver (factor): the matrix does not have the analysed '// &
                            'pattern (call analyse again after changing the pattern)')
            return
        end if
        status = mc_sparse_factor(self%handle, int(a%n, c_int64_t), a%colptr, a%rowind, a%values, failed)
        if (status == cholmod_not_posdef) then
            self%failed_column = int(failed)
            if (self%kind == sparse_cholesky) then
                write (buf, '(a,i0,a)') 'sparse Cholesky (CHOLMOD): the matrix is not positive definite '// &
                    '(pivot <= 0 at column ', failed, ')'
            else
                write (buf, '(a,i0,a)') 'sparse LDL^T (CHOLMOD): the matrix is singular '// &
                    '(zero pivot at column ', failed, ')'
            end if
            call make_error(error, trim(buf))
            return
        end if
        if (status < cholmod_ok) then
            call status_error(status, 'sparse numerical factorisation (cholmod_factorize)', error)
            return
        end if
        self%factored = .true.
    end subroutine solver_factor

    !> Solve A x = b with the factor.
    subroutine solver_solve_vec(self, b, x, error)
        !> The factored solver.
        class(sparse_solver_t), intent(inout) :: self
        !> Right-hand side (size n).
        real(wp), contiguous, intent(in) :: b(:)
        !> Solution (size n).
        real(wp), contiguous, intent(inout) :: x(:)
        !> Set when not factored, sizes disagree or CHOLMOD fails.
        type(error_t), allocatable, intent(out) :: error
        call solve_common(self, b, x, 1_i8, size(b, kind=i8), size(x, kind=i8), error)
    end subroutine solver_solve_vec

    !> Solve A X = B for the columns of B with the factor.
    subroutine solver_solve_mat(self, b, x, error)
        !> The factored solver.
        class(sparse_solver_t), intent(inout) :: self
        !> Right-hand sides (n, nrhs).
        real(wp), contiguous, intent(in) :: b(:, :)
        !> Solutions (n, nrhs).
        real(wp), contiguous, intent(inout) :: x(:, :)
        !> Set when not factored, sizes disagree or CHOLMOD fails.
        type(error_t), allocatable, intent(out) :: error
        if (size(b, 2) /= size(x, 2)) then
            call make_error(error, 'sparse solve: b and x have different numbers of columns')
            return
        end if
        call solve_common(self, b, x, size(b, 2, kind=i8), size(b, 1, kind=i8), size(x, 1, kind=i8), error)
    end subroutine solver_solve_mat

    ! The solve for nrhs columns of length nb (b) and nx (x), stored contiguously.
    subroutine solve_common(self, b, x, nrhs, nb, nx, error)
        class(sparse_solver_t), intent(inout) :: self
        real(wp), intent(in) :: b(*)
        real(wp), intent(inout) :: x(*)
        integer(i8), intent(in) :: nrhs, nb, nx
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: status
        if (.not. self%factored) then
            call make_error(error, 'sparse solve: the matrix is not factored (call factor first, '// &
                            'and again after a failed factorisation)')
            return
        end if
        if (nb /= self%n .or. nx /= self%n) then
            call make_internal_error(error, 'sparse solve', 'right-hand side or solution of the wrong size')
            return
        end if
        if (nrhs == 0) return
        status = mc_sparse_solve(self%handle, int(self%n, c_int64_t), nrhs, b, x)
        if (status < cholmod_ok) call status_error(status, 'sparse solve (cholmod_solve2)', error)
    end subroutine solve_common

    !> Replace rows and columns `rows` of the factored matrix A by those of the identity: the
    !> factor is modified in place (cholmod_rowdel on each row, in the given order) and
    !> then solves the matrix equal to A but for A(r, :) = A(:, r) = e_r for every deleted
    !> r, whose other rows are exact without a new analysis or factorisation; a right-hand
    !> side zero on the deleted rows has a solution zero there. The cost of a deletion
    !> is that of the columns of the factor it changes, a small part of a factorisation.
    !> CHOLMOD modifies only a simplicial L D L^T factor: a supernodal or L L^T one is
    !> converted to it first (once; `factor` then refactors in that form, and `stats`
    !> reports it). Deleting a row already deleted changes nothing.
    subroutine solver_delete_rows(self, rows, error)
        !> The factored solver.
        class(sparse_solver_t), intent(inout) :: self
        !> Rows (1-based, original numbering, 1..n) to delete, in order.
        integer, intent(in) :: rows(:)
        !> Set when not factored, a row is outside 1..n, or CHOLMOD fails (out of memory: the
        !> factor is then no longer usable and `factor` must be called again).
        type(error_t), allocatable, intent(out) :: error
        integer(c_int) :: status
        if (.not. self%factored) then
            call make_error(error, 'sparse delete_rows: the matrix is not factored (call factor first)')
            return
        end if
        if (size(rows) == 0) return
        if (any(rows < 1) .or. any(rows > self%n)) then
            call make_internal_error(error, 'sparse delete_rows', 'row outside 1..n')
            return
        end if
        status = mc_sparse_delete(self%handle, size(rows, kind=c_int64_t), int(rows - 1, c_int64_t))
        if (status < cholmod_ok) then
            self%factored = .false.
            call status_error(status, 'sparse row deletion (cholmod_rowdel)', error)
        end if
    end subroutine solver_delete_rows

    !> Figures of the last analysis and factorisation (zeros and 'none' before `analyse`).
    function solver_stats(self) result(stats)
        !> The solver.
        class(sparse_solver_t), intent(in) :: self
        !> The figures.
        type(sparse_stats_t) :: stats
        real(c_double) :: lnz, flops, rcond, memory_peak
        integer(c_int) :: ordering, supernodal, is_ll
        integer(c_int64_t) :: negative
        stats%ordering = 'none'
        if (.not. self%analysed) return
        call mc_sparse_info(self%handle, lnz, flops, ordering, supernodal, is_ll, negative, rcond, memory_peak)
        stats%n = self%n
        stats%nnz_matrix = self%nnz
        stats%nnz_factor = lnz
        stats%flops = flops
        ! CHOLMOD's codes: CHOLMOD_NATURAL 0, GIVEN 1, AMD 2, METIS 3, NESDIS 4, COLAMD 5.
        select case (ordering)
        case (0)
            stats%ordering = 'natural'
        case (1)
            stats%ordering = 'given'
        case (2)
            stats%ordering = 'amd'
        case (3)
            stats%ordering = 'metis'
        case (4)
            stats%ordering = 'nesdis'
        case (5)
            stats%ordering = 'colamd'
        case default
            stats%ordering = 'unknown'
        end select
        stats%supernodal = supernodal /= 0
        stats%ll = is_ll /= 0
        if (self%factored) then
            stats%negative_pivots = negative
            stats%rcond = rcond
        end if
        stats%memory_peak = memory_peak
    end function solver_stats

    !> True after a successful `factor`.
    pure function solver_is_factored(self) result(factored)
        !> The solver.
        class(sparse_solver_t), intent(in) :: self
        !> Whether `solve` may be called.
        logical :: factored
        factored = self%factored
    end function solver_is_factored

    !> Free CHOLMOD's memory; the solver returns to its initial state (kind and ordering
    !> kept).
    subroutine solver_destroy(self)
        !> The solver.
        class(sparse_solver_t), intent(inout) :: self
        if (c_associated(self%handle)) call mc_sparse_destroy(self%handle)
        self%handle = c_null_ptr
        self%n = 0
        self%nnz = 0
        self%pattern_sum = 0
        self%analysed = .false.
        self%factored = .false.
        self%failed_column = 0
    end subroutine solver_destroy

    ! Finaliser: frees CHOLMOD's memory when the object goes away.
    subroutine solver_final(self)
        type(sparse_solver_t), intent(inout) :: self
        call solver_destroy(self)
    end subroutine solver_final

    !> Defined assignment: a deep copy (own CHOLMOD object, copied factor), so that two
    !> objects never share, and free twice, one CHOLMOD handle.
    subroutine solver_assign(lhs, rhs)
        !> The copy.
        class(sparse_solver_t), intent(inout) :: lhs
        !> The solver copied.
        class(sparse_solver_t), intent(in) :: rhs
        if (c_associated(lhs%handle) .and. c_associated(rhs%handle)) then
            if (c_associated(lhs%handle, rhs%handle)) return
        end if
        call solver_destroy(lhs)
        lhs%kind = rhs%kind
        lhs%ordering = rhs%ordering
        if (.not. c_associated(rhs%handle)) return
        lhs%handle = mc_sparse_copy(rhs%handle)
        ! Out of memory: lhs stays empty (not analysed) and says so at its next factor/solve.
        if (.not. c_associated(lhs%handle)) return
        lhs%n = rhs%n
        lhs%nnz = rhs%nnz
        lhs%pattern_sum = rhs%pattern_sum
        lhs%analysed = rhs%analysed
        lhs%factored = rhs%factored
        lhs%failed_column = rhs%failed_column
    end subroutine solver_assign

    ! Checksum of the pattern (column starts and row indices), to detect a factorisation
    ! with another pattern than the analysed one. Arithmetic modulo the prime 2^31 - 1 keeps
    ! every intermediate below 2^47 (no overflow).
    pure function pattern_checksum(a) result(sum)
        type(sparse_matrix_t), intent(in) :: a
        integer(i8) :: sum
        integer(i8), parameter :: modulus = 2147483647_i8, multiplier = 48271_i8
        integer(i8) :: k
        sum = 1
        do k = 1, size(a%colptr, kind=i8)
            sum = mod(sum*multiplier + mod(a%colptr(k), modulus), modulus)
        end do
        do k = 1, size(a%rowind, kind=i8)
            sum = mod(sum*multiplier + a%rowind(k), modulus)
        end do
    end function pattern_checksum

    ! Double the triplet storage.
    pure subroutine grow_triplets(self)
        type(sparse_matrix_t), intent(inout) :: self
        integer(i8), allocatable :: itmp(:)
        real(wp), allocatable :: vtmp(:)
        integer(i8) :: cap, m
        m = self%ntriplets
        cap = 2*max(size(self%ti, kind=i8), 1_i8)
        allocate (itmp(cap))
        itmp(1:m) = self%ti(1:m)
        call move_alloc(itmp, self%ti)
        allocate (itmp(cap))
        itmp(1:m) = self%tj(1:m)
        call move_alloc(itmp, self%tj)
        allocate (vtmp(cap))
        vtmp(1:m) = self%tv(1:m)
        call move_alloc(vtmp, self%tv)
    end subroutine grow_triplets

    ! Remember the first invalid entry given to add.
    pure subroutine remember_bad(self, i, j)
        type(sparse_matrix_t), intent(inout) :: self
        integer, intent(in) :: i, j
        if (all(self%bad_entry == 0)) self%bad_entry = [i, j]
    end subroutine remember_bad

    ! Error for an invalid entry remembered by add.
    subroutine check_bad_entry(a, error)
        type(sparse_matrix_t), intent(in) :: a
        type(error_t), allocatable, intent(out) :: error
        character(len=200) :: buf
        if (all(a%bad_entry == 0)) return
        if (a%finalized .and. all(a%bad_entry >= 1) .and. all(a%bad_entry <= a%n)) then
            write (buf, '(a,i0,a,i0,a)') 'sparse matrix: entry (', a%bad_entry(1), ', ', a%bad_entry(2), &
                ') is outside the pattern fixed by finalize (init and assemble again to change it)'
        else
            write (buf, '(a,i0,a,i0,a,i0)') 'sparse matrix: entry (', a%bad_entry(1), ', ', a%bad_entry(2), &
                ') is outside the matrix of order ', a%n
        end if
        call make_error(error, trim(buf))
    end subroutine check_bad_entry

    ! Error for a CHOLMOD status < 0 (or the C layer's missing handle).
    subroutine status_error(status, what, error)
        integer(c_int), intent(in) :: status
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        character(len=32) :: code
        select case (status)
        case (cholmod_not_installed)
            call make_error(error, what//': a CHOLMOD module is missing from the installed '// &
                            'SuiteSparse (e.g. METIS ordering in a build without the Partition module)')
        case (cholmod_out_of_memory)
            call make_error(error, what//': out of memory')
        case (cholmod_too_large)
            call make_error(error, what//': problem too large (integer overflow in CHOLMOD)')
        case (cholmod_invalid)
            call make_internal_error(error, what, 'CHOLMOD refused its input as invalid')
        case (mc_no_handle)
            call make_internal_error(error, what, 'the solver is not analysed')
        case default
            write (code, '(i0)') status
            call make_error(error, what//': CHOLMOD status '//trim(code))
        end select
    end subroutine status_error
end module core_sparse
