!> How an element's mass enters the assembled mass matrix (doc/theory.md, section 5.2), as
!> a family of behaviour chosen once from the deck word `mass` of [beam] and [continuum]:
!> - `consistent_mass_t`: the consistent element mass, whole (M = int rho N^T N);
!> - `lumped_mass_t`: the element's lumped diagonal only (row sums for the 2D elements, HRZ
!>   for the beam), so that M is diagonal (what the central-difference scheme needs).
!>
!> Every element family gives both forms (fem_element2d `mass_consistent` and `mass_lumped`,
!> fem_beam_element `element_mass_consistent` and `element_mass_lumped`, or their alpha-weighted
!> forms in an Arlequin overlap); the scheme picks one and returns it as local entries (row,
!> column, value), which the models add to their own storage (triplets or band):
!> `add_element` for triplets, `element_matrix` for a dense element matrix.
module fem_mass_scheme
    use core_kinds, only: wp
    use core_error, only: error_t, make_internal_error
    use fem_triplets, only: fem_triplets_t
    implicit none
    private
    public :: mass_scheme_t, consistent_mass_t, lumped_mass_t, make_mass_scheme

    !> A way of assembling the mass matrix from the element masses.
    type, abstract :: mass_scheme_t
    contains
        !> Whether the assembled mass matrix is diagonal.
        procedure(scheme_is_diagonal), deferred :: is_diagonal
        !> The element's mass under the scheme, as local entries (row, column, value).
        procedure(scheme_element_entries), deferred :: element_entries
        !> Append an element's mass to triplets at its global dofs (dof 0: skipped).
        procedure, non_overridable :: add_element => scheme_add_element
        !> The element's mass under the scheme as a dense matrix (zero off its entries).
        procedure, non_overridable :: element_matrix => scheme_element_matrix
    end type mass_scheme_t

    !> Consistent mass: every entry of the consistent element mass.
    type, extends(mass_scheme_t) :: consistent_mass_t
    contains
        !> False: the consistent mass couples the dofs of an element.
        procedure :: is_diagonal => consistent_is_diagonal
        !> The consistent element mass, column by column.
        procedure :: element_entries => consistent_element_entries
    end type consistent_mass_t

    !> Lumped mass: the element's lumped diagonal only.
    type, extends(mass_scheme_t) :: lumped_mass_t
    contains
        !> True.
        procedure :: is_diagonal => lumped_is_diagonal
        !> The element's lumped diagonal.
        procedure :: element_entries => lumped_element_entries
    end type lumped_mass_t

    abstract interface
        !> Whether the assembled mass matrix is diagonal.
        pure logical function scheme_is_diagonal(self)
            import :: mass_scheme_t
            !> The scheme.
            class(mass_scheme_t), intent(in) :: self
        end function scheme_is_diagonal

        !> The element's mass under the scheme: entry p is at local row rows(p) and column
        !> cols(p) of the element's dofs, with value values(p); each (row, column) at most once.
        pure subroutine scheme_element_entries(self, consistent, diagonal, rows, cols, values)
            import :: mass_scheme_t, wp
            !> The scheme.
            class(mass_scheme_t), intent(in) :: self
            !> The element's consistent mass (n, n).
            real(wp), intent(in) :: consistent(:, :)
            !> The element's lumped mass, its diagonal (n).
            real(wp), intent(in) :: diagonal(:)
            !> Local row of each entry (1..n).
            integer, allocatable, intent(out) :: rows(:)
            !> Local column of each entry (1..n).
            integer, allocatable, intent(out) :: cols(:)
            !> Value of each entry.
            real(wp), allocatable, intent(out) :: values(:)
        end subroutine scheme_element_entries
    end interface

contains

    !> The scheme named by a deck word of `mass` ([beam] or [continuum]): 'consistent' or
    !> 'lumped'. The schema refuses any other word, so another one here is a bug.
    subroutine make_mass_scheme(word, scheme, error)
        !> The deck word.
        character(len=*), intent(in) :: word
        !> The scheme.
        class(mass_scheme_t), allocatable, intent(out) :: scheme
        !> Set (internal error) for a word that names no scheme.
        type(error_t), allocatable, intent(out) :: error
        select case (word)
        case ('consistent')
            allocate (consistent_mass_t :: scheme)
        case ('lumped')
            allocate (lumped_mass_t :: scheme)
        case default
            call make_internal_error(error, 'make_mass_scheme', 'mass scheme '''//word// &
                                     ''' is none of consistent, lumped (the schema should have refused it)')
        end select
    end subroutine make_mass_scheme

    !> Append the element's mass under the scheme to triplets, in the order of its entries.
    pure subroutine scheme_add_element(self, m, dofs, consistent, diagonal)
        !> The scheme.
        class(mass_scheme_t), intent(in) :: self
        !> The global mass.
        type(fem_triplets_t), intent(inout) :: m
        !> Global dof of each local dof (0: skipped).
        integer, intent(in) :: dofs(:)
        !> The element's consistent mass (n, n).
        real(wp), intent(in) :: consistent(:, :)
        !> The element's lumped mass, its diagonal (n).
        real(wp), intent(in) :: diagonal(:)
        integer, allocatable :: rows(:), cols(:)
        real(wp), allocatable :: values(:)
        integer :: p
        call self%element_entries(consistent, diagonal, rows, cols, values)
        do p = 1, size(values)
            if (dofs(rows(p)) == 0 .or. dofs(cols(p)) == 0) cycle
            call m%add(dofs(rows(p)), dofs(cols(p)), values(p))
        end do
    end subroutine scheme_add_element

    !> The element's mass under the scheme as a dense (n, n) matrix, zero off its entries.
    pure function scheme_element_matrix(self, consistent, diagonal) result(me)
        !> The scheme.
        class(mass_scheme_t), intent(in) :: self
        !> The element's consistent mass (n, n).
        real(wp), intent(in) :: consistent(:, :)
        !> The element's lumped mass, its diagonal (n).
        real(wp), intent(in) :: diagonal(:)
        !> The element mass (n, n).
        real(wp) :: me(size(diagonal), size(diagonal))
        integer, allocatable :: rows(:), cols(:)
        real(wp), allocatable :: values(:)
        integer :: p
        call self%element_entries(consistent, diagonal, rows, cols, values)
        me = 0.0_wp
        do p = 1, size(values)
            me(rows(p), cols(p)) = values(p)
        end do
    end function scheme_element_matrix

    !> False.
    pure logical function consistent_is_diagonal(self)
        !> The scheme.
        class(consistent_mass_t), intent(in) :: self
        consistent_is_diagonal = .false.
    end function consistent_is_diagonal

    !> Every entry of the consistent mass, column by column (rows inner).
    pure subroutine consistent_element_entries(self, consistent, diagonal, rows, cols, values)
        !> The scheme.
        class(consistent_mass_t), intent(in) :: self
        !> The element's consistent mass (n, n).
        real(wp), intent(in) :: consistent(:, :)
        !> The element's lumped mass (unused).
        real(wp), intent(in) :: diagonal(:)
        !> Local row of each entry.
        integer, allocatable, intent(out) :: rows(:)
        !> Local column of each entry.
        integer, allocatable, intent(out) :: cols(:)
        !> Value of each entry.
        real(wp), allocatable, intent(out) :: values(:)
        integer :: a, b, n
        n = size(consistent, 1)
        rows = [((a, a=1, n), b=1, n)]
        cols = [((b, a=1, n), b=1, n)]
        values = reshape(consistent, [n*n])
    end subroutine consistent_element_entries

    !> True.
    pure logical function lumped_is_diagonal(self)
        !> The scheme.
        class(lumped_mass_t), intent(in) :: self
        lumped_is_diagonal = .true.
    end function lumped_is_diagonal

    !> The lumped diagonal, one entry per dof.
    pure subroutine lumped_element_entries(self, consistent, diagonal, rows, cols, values)
        !> The scheme.
        class(lumped_mass_t), intent(in) :: self
        !> The element's consistent mass (unused).
        real(wp), intent(in) :: consistent(:, :)
        !> The element's lumped mass, its diagonal (n).
        real(wp), intent(in) :: diagonal(:)
        !> Local row of each entry.
        integer, allocatable, intent(out) :: rows(:)
        !> Local column of each entry (its row).
        integer, allocatable, intent(out) :: cols(:)
        !> Value of each entry.
        real(wp), allocatable, intent(out) :: values(:)
        integer :: a
        rows = [(a, a=1, size(diagonal))]
        cols = rows
        values = diagonal
    end subroutine lumped_element_entries
end module fem_mass_scheme
