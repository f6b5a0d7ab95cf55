!> A 2D finite-element mesh: nodes, elements of the kinds of fem_element_registry (T3, Q4), and
!> named node, element and edge sets.
!>
!> Element e is of kind id `kind(e)` and its nodes are stored counter-clockwise in
!> `connectivity(1:n, e)`, n the node count of its kind (the connectivity has max_node_count()
!> rows, 0 beyond the element's nodes: the fourth row of a triangle). Named sets carry the names
!> the deck refers to (Gmsh physical groups, or left/right/bottom/top/all for generated
!> rectangles). Edge sets hold 2-node boundary edges, oriented so that the body lies on their
!> left (outward normal (s_y, -s_x)).
module fem_mesh2d
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, same_name
    use core_utf8, only: invalid_utf8_column, byte_hex
    use fem_element_registry, only: kind_node_count
    implicit none
    private
    public :: mesh2d_t, named_set_t, edge_set_t, physical_group_t, set_name_problem

    !> A named set of node or element indices.
    type :: named_set_t
        !> Name (case-sensitive).
        character(len=:), allocatable :: name
        !> Indices (sorted, unique).
        integer, allocatable :: ids(:)
    end type named_set_t

    !> A named set of 2-node edges.
    type :: edge_set_t
        !> Name (case-sensitive).
        character(len=:), allocatable :: name
        !> Node indices of each edge (2, number of edges), body on the left of a -> b.
        integer, allocatable :: nodes(:, :)
        !> Element of which each edge is a side (0 until `orient_edges` has run).
        integer, allocatable :: elements(:)
    end type edge_set_t

    !> A physical group a mesh file declares by name ($PhysicalNames).
    type :: physical_group_t
        !> Name (case-sensitive).
        character(len=:), allocatable :: name
        !> Dimension: 0 points, 1 lines, 2 surfaces.
        integer :: dim = 0
    end type physical_group_t

    !> The mesh.
    type :: mesh2d_t
        !> Node coordinates (2, number of nodes) (m).
        real(wp), allocatable :: x(:, :)
        !> Element kind id of each element (fem_element_registry: 1 = T3, 2 = Q4).
        integer, allocatable :: kind(:)
        !> Connectivity (max_node_count(), number of elements), counter-clockwise; 0 beyond the
        !> element's nodes.
        integer, allocatable :: connectivity(:, :)
        !> Named node sets.
        type(named_set_t), allocatable :: node_sets(:)
        !> Named element sets.
        type(named_set_t), allocatable :: element_sets(:)
        !> Named edge sets.
        type(edge_set_t), allocatable :: edge_sets(:)
        !> Gmsh tag of each element (unallocated for a generated mesh, whose elements are
        !> named by their index).
        integer, allocatable :: element_tag(:)
        !> Line of each element in the mesh file (with element_tag).
        integer, allocatable :: element_line(:)
        !> The mesh file (with element_tag).
        character(len=:), allocatable :: file
        !> The physical groups the mesh file declares by name, with or without elements
        !> (unallocated for a generated mesh).
        type(physical_group_t), allocatable :: declared(:)
    contains
        !> Number of nodes.
        procedure :: node_count => mesh_node_count
        !> Number of elements.
        procedure :: element_count => mesh_element_count
        !> Node indices of element e.
        procedure :: element_nodes => mesh_element_nodes
        !> Coordinates (2, n) of the nodes of element e.
        procedure :: element_coordinates => mesh_element_coordinates
        !> How messages name element e: its Gmsh tag, file and line when read from a file, its
        !> index otherwise, and its centroid.
        procedure :: element_label => mesh_element_label
        !> Body of each node: the connected parts of the mesh (elements sharing a node).
        procedure :: bodies => mesh_bodies
        !> Add (or extend) a node set.
        procedure :: add_node_set => mesh_add_node_set
        !> Add (or extend) an element set.
        procedure :: add_element_set => mesh_add_element_set
        !> Add (or extend) an edge set.
        procedure :: add_edge_set => mesh_add_edge_set
        !> Indices of a named node set (error when unknown).
        procedure :: node_set => mesh_node_set
        !> Indices of a named element set (error when unknown).
        procedure :: element_set => mesh_element_set
        !> Edges of a named edge set and their elements (error when unknown).
        procedure :: edge_set => mesh_edge_set
        !> Orient every edge of the edge sets so that an element containing it lies on its left,
        !> and record that element.
        procedure :: orient_edges => mesh_orient_edges
        !> Reorder clockwise elements counter-clockwise (by signed area).
        procedure :: orient_elements => mesh_orient_elements
    end type mesh2d_t

contains

    !> Number of nodes.
    pure integer function mesh_node_count(self)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        mesh_node_count = 0
        if (allocated(self%x)) mesh_node_count = size(self%x, 2)
    end function mesh_node_count

    !> Number of elements.
    pure integer function mesh_element_count(self)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        mesh_element_count = 0
        if (allocated(self%kind)) mesh_element_count = size(self%kind)
    end function mesh_element_count

    !> Node indices of element e.
    pure function mesh_element_nodes(self, e) result(nodes)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Element index.
        integer, intent(in) :: e
        !> Its nodes, counter-clockwise.
        integer, allocatable :: nodes(:)
        nodes = self%connectivity(1:kind_node_count(self%kind(e)), e)
    end function mesh_element_nodes

    !> Coordinates of the nodes of element e.
    pure function mesh_element_coordinates(self, e) result(xe)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Element index.
        integer, intent(in) :: e
        !> Coordinates (2, nodes of the element).
        real(wp), allocatable :: xe(:, :)
        xe = self%x(:, self%connectivity(1:kind_node_count(self%kind(e)), e))
    end function mesh_element_coordinates

    !> 'Gmsh element 29 (plate.msh:187, centroid (0.5, 0.25) m)' for an element read from a
    !> Gmsh file (its tag and line there: the index in the mesh is no number the user can
    !> find), 'element 3 (centroid (0.5, 0.25) m)' for a generated mesh.
    function mesh_element_label(self, e) result(label)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Element index.
        integer, intent(in) :: e
        !> The label.
        character(len=:), allocatable :: label
        real(wp), allocatable :: xe(:, :)
        character(len=:), allocatable :: centroid
        xe = self%element_coordinates(e)
        centroid = 'centroid ('//to_str(sum(xe(1, :))/size(xe, 2))//', '//to_str(sum(xe(2, :))/size(xe, 2))//') m)'
        label = 'element '//to_str(e)//' ('//centroid
        if (.not. (allocated(self%element_tag) .and. allocated(self%element_line) .and. allocated(self%file))) return
        if (size(self%element_tag) /= self%element_count() .or. size(self%element_line) /= self%element_count()) return
        label = 'Gmsh element '//to_str(self%element_tag(e))//' ('//self%file//':'//to_str(self%element_line(e))// &
                ', '//centroid
    end function mesh_element_label

    !> Body of each node, numbered 1..count in the order of their first node: two elements
    !> sharing a node are in the same body (union-find over the connectivity); a node in no
    !> element is a body of its own.
    pure subroutine mesh_bodies(self, body, count)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Body of each node (number of nodes).
        integer, allocatable, intent(out) :: body(:)
        !> Number of bodies.
        integer, intent(out) :: count
        integer, allocatable :: parent(:), number(:)
        integer :: e, k, a, ra, r0
        allocate (parent(self%node_count()))
        parent = [(a, a=1, self%node_count())]
        do e = 1, self%element_count()
            call find_root(parent, self%connectivity(1, e), r0)
            do k = 2, kind_node_count(self%kind(e))
                call find_root(parent, self%connectivity(k, e), ra)
                ! The larger root under the smaller: a root stays the smallest node of its body.
                parent(max(ra, r0)) = min(ra, r0)
                r0 = min(ra, r0)
            end do
        end do
        allocate (body(self%node_count()), number(self%node_count()), source=0)
        count = 0
        do a = 1, self%node_count()
            call find_root(parent, a, ra)
            if (number(ra) == 0) then
                count = count + 1
                number(ra) = count
            end if
            body(a) = number(ra)
        end do

    contains

        !> Root of a node's tree, each node on the way pointed at its grandparent (path halving).
        pure subroutine find_root(parent, node, r)
            integer, intent(inout) :: parent(:)
            integer, intent(in) :: node
            integer, intent(out) :: r
            r = node
            do while (parent(r) /= r)
                parent(r) = parent(parent(r))
                r = parent(r)
            end do
        end subroutine find_root
    end subroutine mesh_bodies

    !> Sorted unique copy of a list of positive indices (by marking: O(size + max)).
    pure function sorted_unique(ids) result(out)
        integer, intent(in) :: ids(:)
        integer, allocatable :: out(:)
        logical, allocatable :: mark(:)
        integer :: k
        allocate (mark(max(0, maxval(ids))), source=.false.)
        mark(ids) = .true.
        out = pack([(k, k=1, size(mark))], mark)
    end function sorted_unique

    !> Why `name` cannot name a set ('' when it can). The results file stores each set as an
    !> HDF5 link named after it (/continuum/sets/nodes/<name>), where '/' separates groups and
    !> '.' is the group itself, and HDF5's Fortran interface drops the trailing blanks of a link
    !> name: a name with '/' was stored under another name ('a/b' as dataset b of a group a) or
    !> failed the write, '.' failed it, 'a ' was stored as 'a'. HDF5 stores '..', but tools that
    !> resolve paths (Python's posixpath.normpath) read it as the parent group: refused with '.'.
    !> A blank name (blanks and tabs only) is refused too, and so is a name that is not UTF-8
    !> text (h5py returns it as bytes, not as a string). Leading blanks and tabs are kept.
    pure function set_name_problem(name) result(why)
        !> The name, as written.
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: why
        character(len=*), parameter :: stored = 'the results file stores each set as an HDF5 link named after it'
        integer :: bad
        why = ''
        bad = invalid_utf8_column(name)
        if (bad > 0) then
            why = 'the name holds byte '//byte_hex(name(bad:bad))//' (its byte '//to_str(bad)//'), which is not UTF-8 '// &
                  'text (a .geo file saved as Latin-1 or Windows-1252?): '//stored//', which readers such as h5py '// &
                  'decode as UTF-8 (they return such a name as raw bytes); save the .geo file as UTF-8 and mesh it again'
        else if (verify(name, ' '//achar(9)) == 0) then
            why = 'the name is blank: a set name needs a character other than a blank'
        else if (index(name, '/') > 0) then
            why = 'the name holds a ''/'': '//stored//', where ''/'' separates groups'
        else if (same_name(name, '.') .or. same_name(name, '..')) then
            why = 'the name is '''//name//''': '//stored//', where ''.'' is the group itself and ''..'' its '// &
                  'parent in a path'
        else if (name(len(name):) == ' ') then
            why = 'the name ends in a blank: '//stored//', and HDF5 drops the trailing blanks of a link name (it '// &
                  'would be stored as "'//trim(name)//'", another name)'
        end if
    end function set_name_problem

    !> Index of the set called name in sets (0 if none): the name exactly, so that 'a' and
    !> 'a ' (a Gmsh group with a trailing blank) are two sets.
    pure integer function find_set(sets, name) result(k)
        type(named_set_t), allocatable, intent(in) :: sets(:)
        character(len=*), intent(in) :: name
        k = 0
        if (.not. allocated(sets)) return
        do k = 1, size(sets)
            if (same_name(sets(k)%name, name)) return
        end do
        k = 0
    end function find_set

    !> Add ids to the named set, creating it when new.
    pure subroutine add_to_sets(sets, name, ids)
        type(named_set_t), allocatable, intent(inout) :: sets(:)
        character(len=*), intent(in) :: name
        integer, intent(in) :: ids(:)
        type(named_set_t), allocatable :: grown(:)
        integer, allocatable :: merged(:)
        integer :: k
        if (.not. allocated(sets)) allocate (sets(0))
        k = find_set(sets, name)
        if (k == 0) then
            allocate (grown(size(sets) + 1))
            do k = 1, size(sets)
                call move_alloc(sets(k)%name, grown(k)%name)
                call move_alloc(sets(k)%ids, grown(k)%ids)
            end do
            grown(size(grown))%name = name
            grown(size(grown))%ids = sorted_unique(ids)
            call move_alloc(grown, sets)
        else
            allocate (merged(size(sets(k)%ids) + size(ids)))
            merged(1:size(sets(k)%ids)) = sets(k)%ids
            merged(size(sets(k)%ids) + 1:) = ids
            sets(k)%ids = sorted_unique(merged)
        end if
    end subroutine add_to_sets

    !> Add node indices to a named node set (created when new).
    pure subroutine mesh_add_node_set(self, name, ids)
        !> The mesh.
        class(mesh2d_t), intent(inout) :: self
        !> Set name.
        character(len=*), intent(in) :: name
        !> Node indices.
        integer, intent(in) :: ids(:)
        call add_to_sets(self%node_sets, name, ids)
    end subroutine mesh_add_node_set

    !> Add element indices to a named element set (created when new).
    pure subroutine mesh_add_element_set(self, name, ids)
        !> The mesh.
        class(mesh2d_t), intent(inout) :: self
        !> Set name.
        character(len=*), intent(in) :: name
        !> Element indices.
        integer, intent(in) :: ids(:)
        call add_to_sets(self%element_sets, name, ids)
    end subroutine mesh_add_element_set

    !> Add edges to a named edge set (created when new).
    pure subroutine mesh_add_edge_set(self, name, edges)
        !> The mesh.
        class(mesh2d_t), intent(inout) :: self
        !> Set name.
        character(len=*), intent(in) :: name
        !> Node indices of the edges (2, n).
        integer, intent(in) :: edges(:, :)
        integer :: k
        integer, allocatable :: merged(:, :)
        type(edge_set_t), allocatable :: grown(:)
        if (.not. allocated(self%edge_sets)) allocate (self%edge_sets(0))
        do k = 1, size(self%edge_sets)
            if (same_name(self%edge_sets(k)%name, name)) then
                allocate (merged(2, size(self%edge_sets(k)%nodes, 2) + size(edges, 2)))
                merged(:, 1:size(self%edge_sets(k)%nodes, 2)) = self%edge_sets(k)%nodes
                merged(:, size(self%edge_sets(k)%nodes, 2) + 1:) = edges
                call move_alloc(merged, self%edge_sets(k)%nodes)
                self%edge_sets(k)%elements = [self%edge_sets(k)%elements, spread(0, 1, size(edges, 2))]
                return
            end if
        end do
        allocate (grown(size(self%edge_sets) + 1))
        do k = 1, size(self%edge_sets)
            call move_alloc(self%edge_sets(k)%name, grown(k)%name)
            call move_alloc(self%edge_sets(k)%nodes, grown(k)%nodes)
            call move_alloc(self%edge_sets(k)%elements, grown(k)%elements)
        end do
        grown(size(grown))%name = name
        grown(size(grown))%nodes = edges
        allocate (grown(size(grown))%elements(size(edges, 2)), source=0)
        call move_alloc(grown, self%edge_sets)
    end subroutine mesh_add_edge_set

    !> Sorted node indices of a named node set.
    subroutine mesh_node_set(self, name, ids, error)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Set name.
        character(len=*), intent(in) :: name
        !> Node indices.
        integer, allocatable, intent(out) :: ids(:)
        !> Set when no node set has that name.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        k = find_set(self%node_sets, name)
        if (k == 0) then
            call make_error(error, "mesh: no node set named '"//name//"'"//empty_group(self, name, [0, 1, 2])// &
                            known(self%node_sets))
            return
        end if
        ids = self%node_sets(k)%ids
    end subroutine mesh_node_set

    !> Sorted element indices of a named element set.
    subroutine mesh_element_set(self, name, ids, error)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Set name.
        character(len=*), intent(in) :: name
        !> Element indices.
        integer, allocatable, intent(out) :: ids(:)
        !> Set when no element set has that name.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        k = find_set(self%element_sets, name)
        if (k == 0) then
            call make_error(error, "mesh: no element set named '"//name//"'"//empty_group(self, name, [2])// &
                            known(self%element_sets))
            return
        end if
        ids = self%element_sets(k)%ids
    end subroutine mesh_element_set

    !> Edges of a named edge set.
    subroutine mesh_edge_set(self, name, edges, error, elements)
        !> The mesh.
        class(mesh2d_t), intent(in) :: self
        !> Set name.
        character(len=*), intent(in) :: name
        !> Node indices of the edges (2, n).
        integer, allocatable, intent(out) :: edges(:, :)
        !> Set when no edge set has that name.
        type(error_t), allocatable, intent(out) :: error
        !> Element of which each edge is a side (0 before `orient_edges`).
        integer, allocatable, intent(out), optional :: elements(:)
        integer :: k
        character(len=:), allocatable :: names
        if (allocated(self%edge_sets)) then
            do k = 1, size(self%edge_sets)
                if (same_name(self%edge_sets(k)%name, name)) then
                    edges = self%edge_sets(k)%nodes
                    if (present(elements)) elements = self%edge_sets(k)%elements
                    return
                end if
            end do
        end if
        names = ''
        if (allocated(self%edge_sets)) then
            do k = 1, size(self%edge_sets)
                if (k > 1) names = names//','
                names = names//" '"//self%edge_sets(k)%name//"'"
            end do
        end if
        if (len(names) == 0) names = ' (none)'
        call make_error(error, "mesh: no edge set named '"//name//"'"//empty_group(self, name, [1])//' (known:'// &
                        names//')')
    end subroutine mesh_edge_set

    !> ": 'name' is declared in $PhysicalNames of <file> (dimension d) but holds no elements
    !> of that dimension" when the mesh file declares a group of that name and one of the
    !> dimensions `dims` (that of the set looked for: no set was made of it), else ''.
    pure function empty_group(self, name, dims) result(text)
        type(mesh2d_t), intent(in) :: self
        character(len=*), intent(in) :: name
        integer, intent(in) :: dims(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        if (.not. allocated(self%declared)) return
        do k = 1, size(self%declared)
            if (.not. same_name(self%declared(k)%name, name)) cycle
            if (.not. any(dims == self%declared(k)%dim)) cycle
            text = ": '"//name//"' is declared in $PhysicalNames"
            if (allocated(self%file)) text = text//' of '//self%file
            text = text//' (dimension '//to_str(self%declared(k)%dim)//') but holds no elements of that dimension'
            return
        end do
    end function empty_group

    !> " (known: 'a', 'b')" listing the names of sets.
    pure function known(sets) result(text)
        type(named_set_t), allocatable, intent(in) :: sets(:)
        character(len=:), allocatable :: text
        integer :: k
        text = ' (known:'
        if (allocated(sets)) then
            do k = 1, size(sets)
                if (k > 1) text = text//','
                text = text//" '"//sets(k)%name//"'"
            end do
            if (size(sets) == 0) text = text//' none'
        else
            text = text//' none'
        end if
        text = text//')'
    end function known

    !> Reorder the nodes of clockwise elements (negative signed area) counter-clockwise.
    pure subroutine mesh_orient_elements(self)
        !> The mesh.
        class(mesh2d_t), intent(inout) :: self
        integer :: e, n
        integer, allocatable :: nodes(:)
        real(wp), allocatable :: xe(:, :)
        real(wp) :: twice_area
        do e = 1, self%element_count()
            nodes = self%element_nodes(e)
            xe = self%x(:, nodes)
            n = size(nodes)
            twice_area = sum(xe(1, :)*cshift(xe(2, :), 1) - cshift(xe(1, :), 1)*xe(2, :))
            if (twice_area < 0.0_wp) self%connectivity(1:n, e) = nodes(n:1:-1)
        end do
    end subroutine mesh_orient_elements

    !> Orient each edge a -> b of the edge sets as a side of a counter-clockwise element (a
    !> followed by b among its nodes), so that the element lies on the edge's left.
    !> An edge in no element is an error; an interior edge takes the first element found.
    subroutine mesh_orient_edges(self, error, failed)
        !> The mesh.
        class(mesh2d_t), intent(inout) :: self
        !> Set when an edge is not a side of any element.
        type(error_t), allocatable, intent(out) :: error
        !> With an error: the edge set and the index of the edge in it.
        integer, intent(out), optional :: failed(2)
        integer, allocatable :: start(:), list(:), fill(:), nodes(:)
        integer :: e, k, a, b, s, m, i, n, p
        character(len=80) :: buf
        logical :: found
        if (.not. allocated(self%edge_sets)) return
        ! Node -> elements adjacency in compressed rows.
        allocate (start(self%node_count() + 1), source=0)
        do e = 1, self%element_count()
            nodes = self%element_nodes(e)
            start(nodes + 1) = start(nodes + 1) + 1
        end do
        start(1) = 1
        do i = 1, self%node_count()
            start(i + 1) = start(i + 1) + start(i)
        end do
        allocate (list(start(self%node_count() + 1) - 1), fill(self%node_count()), source=0)
        fill = start(1:self%node_count())
        do e = 1, self%element_count()
            nodes = self%element_nodes(e)
            list(fill(nodes)) = e
            fill(nodes) = fill(nodes) + 1
        end do
        do s = 1, size(self%edge_sets)
            do k = 1, size(self%edge_sets(s)%nodes, 2)
                a = self%edge_sets(s)%nodes(1, k)
                b = self%edge_sets(s)%nodes(2, k)
                found = .false.
                do m = start(a), start(a + 1) - 1
                    nodes = self%element_nodes(list(m))
                    n = size(nodes)
                    do i = 1, n
                        p = merge(1, i + 1, i == n)
                        if (nodes(i) == a .and. nodes(p) == b) then
                            found = .true.
                        else if (nodes(i) == b .and. nodes(p) == a) then
                            self%edge_sets(s)%nodes(:, k) = [b, a]
                            found = .true.
                        end if
                        if (found) self%edge_sets(s)%elements(k) = list(m)
                        if (found) exit
                    end do
                    if (found) exit
                end do
                if (.not. found) then
                    if (present(failed)) failed = [s, k]
                    write (buf, '(a,i0,a,i0,a,i0)') ': edge ', k, ' (nodes ', a, ', ', b
                    call make_error(error, "mesh: edge set '"//self%edge_sets(s)%name//"'"// &
                                    trim(buf)//') is not a side of any element')
                    return
                end if
            end do
        end do
    end subroutine mesh_orient_edges
end module fem_mesh2d
