!> The registry of the 2D element kinds: `new_element` maps a kind id to an element object,
!> and every other question about the kinds (which kind a deck name or a Gmsh element type
!> denotes, how many kinds there are, the most nodes an element has) is answered by asking the
!> elements it makes. A new element kind is a new module extending `element2d_t` and one case
!> in `new_element` (plus its deck word in the schema and its memory figure in the driver,
!> doc/continuum.md).
!>
!> Kind ids are what a mesh stores for each element (`mesh2d_t%kind`) and what the results file
!> holds in /continuum/mesh/kind: 1 = T3, 2 = Q4; a new kind takes the next id.
!>
!> The element is returned in a slot (a derived type holding it) rather than as a polymorphic
!> function result or dummy: a pure procedure may not have a polymorphic INTENT(OUT) dummy, and
!> gfortran 12 leaks the polymorphic result of a function assigned to a variable.
module fem_element_registry
    use fem_element2d, only: element2d_t
    use fem_element_q4, only: element_q4_t
    use fem_element_t3, only: element_t3_t
    implicit none
    private
    public :: element_slot_t, new_element, element_family, kind_count, kind_of_name, kind_of_gmsh_type, &
              kind_node_count, max_node_count

    !> An element object of one kind.
    type :: element_slot_t
        !> The element (stateless: one serves every element of its kind); unallocated for an
        !> unknown kind.
        class(element2d_t), allocatable :: element
    end type element_slot_t

contains

    !> The element of kind id `kind` (unallocated when no kind has that id).
    pure subroutine new_element(kind, slot)
        !> Kind id (1, 2, ...).
        integer, intent(in) :: kind
        !> Holds the new element.
        type(element_slot_t), intent(out) :: slot
        select case (kind)
        case (1)
            allocate (element_t3_t :: slot%element)
        case (2)
            allocate (element_q4_t :: slot%element)
        end select
    end subroutine new_element

    !> One element of every kind, indexed by kind id.
    pure subroutine element_family(family)
        !> The elements (kind_count()).
        type(element_slot_t), allocatable, intent(out) :: family(:)
        integer :: kind
        allocate (family(kind_count()))
        do kind = 1, size(family)
            call new_element(kind, family(kind))
        end do
    end subroutine element_family

    !> Number of element kinds (their ids are 1..kind_count()).
    pure integer function kind_count()
        type(element_slot_t) :: slot
        kind_count = 0
        do
            call new_element(kind_count + 1, slot)
            if (.not. allocated(slot%element)) return
            kind_count = kind_count + 1
        end do
    end function kind_count

    !> Kind id of the element named `name` in the deck (e.g. 'q4'); 0 when none is.
    pure integer function kind_of_name(name) result(kind)
        !> The deck name.
        character(len=*), intent(in) :: name
        type(element_slot_t) :: slot
        do kind = 1, kind_count()
            call new_element(kind, slot)
            if (slot%element%name() == name) return
        end do
        kind = 0
    end function kind_of_name

    !> Kind id of the element of Gmsh element type `type` (e.g. 3 for the 4-node quadrangle);
    !> 0 when no kind has it (lines, points and unsupported elements).
    pure integer function kind_of_gmsh_type(type) result(kind)
        !> The Gmsh element type number.
        integer, intent(in) :: type
        type(element_slot_t) :: slot
        do kind = 1, kind_count()
            call new_element(kind, slot)
            if (slot%element%gmsh_type() == type) return
        end do
        kind = 0
    end function kind_of_gmsh_type

    !> Number of nodes of an element of kind id `kind` (0 for an unknown kind).
    pure integer function kind_node_count(kind)
        !> Kind id.
        integer, intent(in) :: kind
        type(element_slot_t) :: slot
        call new_element(kind, slot)
        kind_node_count = 0
        if (allocated(slot%element)) kind_node_count = slot%element%node_count()
    end function kind_node_count

    !> Most nodes of an element of any kind: the rows of a mesh's connectivity.
    pure integer function max_node_count()
        integer :: kind
        max_node_count = 0
        do kind = 1, kind_count()
            max_node_count = max(max_node_count, kind_node_count(kind))
        end do
    end function max_node_count
end module fem_element_registry
