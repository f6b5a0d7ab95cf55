!> Sparse matrices in coordinate (triplet, COO) form: the output of the continuum assembly.
!>
!> Entries (i, j, v) are appended as they come; duplicates are allowed and mean a sum (as in
!> CHOLMOD's `cholmod_triplet` with stype 0 and in MUMPS' assembled input). Both triangles of a
!> symmetric matrix are stored. A solver wrapper converts the triplets once (compressed columns);
!> small problems and tests go through `to_dense` or `to_band` and the LAPACK wrappers.
module fem_triplets
    use core_kinds, only: wp
    implicit none
    private
    public :: fem_triplets_t

    !> An n x n sparse matrix as a list of (row, column, value) triplets, duplicates summed.
    type :: fem_triplets_t
        !> Order of the matrix.
        integer :: n = 0
        !> Number of stored triplets.
        integer :: nnz = 0
        !> Row indices (1..n) of the first `nnz` entries.
        integer, allocatable :: i(:)
        !> Column indices (1..n) of the first `nnz` entries.
        integer, allocatable :: j(:)
        !> Values of the first `nnz` entries.
        real(wp), allocatable :: v(:)
    contains
        !> Start an empty n x n matrix with room for `capacity` triplets.
        procedure :: init => triplets_init
        !> Append one triplet.
        procedure :: add => triplets_add
        !> Append a dense block `block(a, b)` at rows and columns `dofs(a)`, `dofs(b)`;
        !> entries whose dof is 0 are skipped.
        procedure :: add_block => triplets_add_block
        !> y = A x.
        procedure :: matvec => triplets_matvec
        !> Dense copy (n, n), duplicates summed.
        procedure :: to_dense => triplets_to_dense
        !> Largest |i - j| over the stored entries (half-bandwidth).
        procedure :: bandwidth => triplets_bandwidth
    end type fem_triplets_t

contains

    !> Start an empty n x n matrix.
    pure subroutine triplets_init(self, n, capacity)
        !> The matrix.
        class(fem_triplets_t), intent(inout) :: self
        !> Order.
        integer, intent(in) :: n
        !> Expected number of triplets (storage grows beyond it when needed).
        integer, intent(in) :: capacity
        self%n = n
        self%nnz = 0
        if (allocated(self%i)) deallocate (self%i, self%j, self%v)
        allocate (self%i(max(capacity, 16)), self%j(max(capacity, 16)), self%v(max(capacity, 16)))
    end subroutine triplets_init

    !> Make room for `extra` more triplets (doubling the storage when full).
    pure subroutine reserve(self, extra)
        type(fem_triplets_t), intent(inout) :: self
        integer, intent(in) :: extra
        integer, allocatable :: itmp(:), jtmp(:)
        real(wp), allocatable :: vtmp(:)
        integer :: cap
        if (.not. allocated(self%i)) allocate (self%i(16), self%j(16), self%v(16))
        if (self%nnz + extra <= size(self%i)) return
        cap = max(2*size(self%i), self%nnz + extra)
        allocate (itmp(cap), jtmp(cap), vtmp(cap))
        itmp(1:self%nnz) = self%i(1:self%nnz)
        jtmp(1:self%nnz) = self%j(1:self%nnz)
        vtmp(1:self%nnz) = self%v(1:self%nnz)
        call move_alloc(itmp, self%i)
        call move_alloc(jtmp, self%j)
        call move_alloc(vtmp, self%v)
    end subroutine reserve

    !> Append the triplet (i, j, v).
    pure subroutine triplets_add(self, i, j, v)
        !> The matrix.
        class(fem_triplets_t), intent(inout) :: self
        !> Row and column (1..n).
        integer, intent(in) :: i, j
        !> Value (added to any other entry at (i, j)).
        real(wp), intent(in) :: v
        call reserve(self, 1)
        self%nnz = self%nnz + 1
        self%i(self%nnz) = i
        self%j(self%nnz) = j
        self%v(self%nnz) = v
    end subroutine triplets_add

    !> Append a dense element block; rows/columns with dof 0 are skipped.
    pure subroutine triplets_add_block(self, dofs, block)
        !> The matrix.
        class(fem_triplets_t), intent(inout) :: self
        !> Global dof of each local row/column (0: skip).
        integer, intent(in) :: dofs(:)
        !> Element matrix (size(dofs), size(dofs)).
        real(wp), intent(in) :: block(:, :)
        integer :: a, b
        call reserve(self, size(dofs)**2)
        do b = 1, size(dofs)
            if (dofs(b) == 0) cycle
            do a = 1, size(dofs)
                if (dofs(a) == 0) cycle
                self%nnz = self%nnz + 1
                self%i(self%nnz) = dofs(a)
                self%j(self%nnz) = dofs(b)
                self%v(self%nnz) = block(a, b)
            end do
        end do
    end subroutine triplets_add_block

    !> y = A x.
    pure subroutine triplets_matvec(self, x, y)
        !> The matrix.
        class(fem_triplets_t), intent(in) :: self
        !> Vector (size n).
        real(wp), intent(in) :: x(:)
        !> Product (size n).
        real(wp), intent(out) :: y(:)
        integer :: k
        y = 0.0_wp
        do k = 1, self%nnz
            y(self%i(k)) = y(self%i(k)) + self%v(k)*x(self%j(k))
        end do
    end subroutine triplets_matvec

    !> Dense copy of the matrix, duplicates summed.
    pure subroutine triplets_to_dense(self, a)
        !> The matrix.
        class(fem_triplets_t), intent(in) :: self
        !> Dense matrix (n, n).
        real(wp), allocatable, intent(out) :: a(:, :)
        integer :: k
        allocate (a(self%n, self%n), source=0.0_wp)
        do k = 1, self%nnz
            a(self%i(k), self%j(k)) = a(self%i(k), self%j(k)) + self%v(k)
        end do
    end subroutine triplets_to_dense

    !> Half-bandwidth max |i - j| of the stored entries (0 for an empty matrix).
    pure integer function triplets_bandwidth(self) result(kd)
        !> The matrix.
        class(fem_triplets_t), intent(in) :: self
        kd = 0
        if (self%nnz > 0) kd = maxval(abs(self%i(1:self%nnz) - self%j(1:self%nnz)))
    end function triplets_bandwidth
end module fem_triplets
