!> Reader of Gmsh meshes, format 4.1 ASCII (`gmsh -2 -format msh41`), into a `mesh2d_t`.
!>
!> Sections read: $MeshFormat (version 4.1, ASCII), $PhysicalNames, $Entities (physical tags of
!> each point, curve and surface), $Nodes and $Elements; any other section is skipped. Element
!> types: those of the registered element kinds (fem_element_registry: 2, 3-node triangle, and
!> 3, 4-node quadrangle) become elements, 1 (2-node line) and 15 (point) only feed named sets.
!> A physical group becomes a node set with the nodes of its elements, an element set when it
!> is 2D and an edge set when it is 1D; it is named by its $PhysicalNames entry, or
!> 'physical_<dim>_<tag>' when it has none; one name for groups of two dimensions is refused
!> (their nodes would make one node set). Nodes that belong to no triangle or quadrangle are
!> dropped; elements are turned counter-clockwise and edges are
!> oriented with the body on their left. Malformed input gives an error naming file and line;
!> a count read from the file is checked against the file's size before it sizes an array, and
!> node tags must be numbered nearly contiguously (the node table is indexed by tag).
!>
!> Refused as well: a path that is not a readable file (a directory), an empty file, a second
!> $MeshFormat, $PhysicalNames, $Entities, $Nodes or $Elements section (it replaced the first),
!> a node line without its 3 coordinates, a header count of nodes or elements that is not the
!> blocks' total, a node or element tag outside the header's range or given twice, and two
!> line, triangle or quadrangle elements on the same nodes (an element listed twice: its
!> stiffness, mass or edge load counted twice). Elements that overlap on different nodes are
!> not detected.
module fem_gmsh_reader
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, split_words, parse_real, to_str, same_name, strip
    use core_sort, only: sort_index, sort_in_place
    use fem_mesh2d, only: mesh2d_t, set_name_problem
    use fem_element_registry, only: kind_of_gmsh_type, kind_node_count, max_node_count
    implicit none
    private
    public :: read_gmsh

    !> A Gmsh entity (point, curve or surface) and its physical tags.
    type :: entity_t
        integer :: dim = 0
        integer :: tag = 0
        integer, allocatable :: physical(:)
    end type entity_t

    !> A physical name.
    type :: physical_name_t
        integer :: dim = 0
        integer :: tag = 0
        !> Line of the name in $PhysicalNames.
        integer :: line = 0
        character(len=:), allocatable :: name
    end type physical_name_t

    !> A block of lower-dimensional or 2D elements attached to an entity.
    type :: block_t
        integer :: dim = 0
        integer :: tag = 0
        integer :: type = 0
        !> Node tags (nodes per element, elements).
        integer, allocatable :: nodes(:, :)
        !> First index of the block's elements in the mesh (2D blocks).
        integer :: first = 0
        !> Line of the block header in the file.
        integer :: line = 0
        !> Line of each element in the file.
        integer, allocatable :: lines(:)
        !> Tag of each element.
        integer, allocatable :: tags(:)
    end type block_t

    !> Line-by-line reading state.
    type :: cursor_t
        integer :: unit = -1
        integer :: line = 0
        character(len=:), allocatable :: path
        character(len=:), allocatable :: section
        !> Size of the file in bytes (bounds the counts read from it).
        integer(i8) :: bytes = 0
    end type cursor_t

    !> Node tags may leave gaps, up to this many tags per node (or up to min_tag_span): the
    !> node table is indexed by tag, 16 bytes per tag.
    integer, parameter :: tags_per_node = 8
    !> Tag span always accepted, whatever the number of nodes (16 MiB of node table).
    integer, parameter :: min_tag_span = 2**20
    !> Sections that build the mesh: each may appear once.
    character(len=14), parameter :: mesh_sections(5) = &
                                    [character(len=14) :: '$MeshFormat', '$PhysicalNames', '$Entities', '$Nodes', '$Elements']

contains

    !> Read a Gmsh 4.1 ASCII mesh.
    subroutine read_gmsh(path, mesh, error)
        !> File name.
        character(len=*), intent(in) :: path
        !> The mesh.
        type(mesh2d_t), intent(out) :: mesh
        !> Set when the file cannot be read or is malformed (message names file and line).
        type(error_t), allocatable, intent(out) :: error
        type(cursor_t) :: cur
        character(len=:), allocatable :: text
        type(entity_t), allocatable :: entities(:)
        type(physical_name_t), allocatable :: names(:)
        type(block_t), allocatable :: blocks(:)
        real(wp), allocatable :: xtag(:, :)
        integer :: ios, min_tag, s, k, seen_at(size(mesh_sections))
        logical :: eof, seen_format, seen_nodes, seen_elements
        character(len=256) :: msg
        cur%path = path
        cur%section = ''
        call check_readable(path, error)
        if (allocated(error)) return
        open (newunit=cur%unit, file=path, status='old', action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_input_error(error, path, 0, '', 'cannot open the mesh file: '//trim(msg))
            return
        end if
        inquire (unit=cur%unit, size=cur%bytes)
        if (cur%bytes == 0) then
            close (cur%unit)
            call make_input_error(error, path, 0, '', 'the mesh file is empty (expected a Gmsh 4.1 ASCII mesh)')
            return
        end if
        allocate (entities(0), names(0), blocks(0))
        min_tag = 1
        seen_format = .false.
        seen_nodes = .false.
        seen_elements = .false.
        seen_at = 0
        do
            call next_line(cur, text, eof, error)
            if (allocated(error)) exit
            if (eof) exit
            if (len_trim(text) == 0) cycle
            if (text(1:1) /= '$') then
                call fail(cur, error, 'expected a section header ($Name), found "'//trim(text)//'"')
                exit
            end if
            cur%section = trim(text)
            if (.not. seen_format .and. cur%section /= '$MeshFormat') then
                call fail(cur, error, 'the file must start with $MeshFormat (is this a Gmsh .msh file?)')
                exit
            end if
            ! A loop, not findloc: gfortran 12's findloc misses a shorter deferred-length string.
            s = 0
            do k = 1, size(mesh_sections)
                if (mesh_sections(k) == cur%section) s = k
            end do
            if (s > 0) then
                if (seen_at(s) > 0) then
                    write (msg, '(i0)') seen_at(s)
                    call fail(cur, error, 'second '//cur%section//' section (the first is on line '//trim(msg)// &
                              '): a mesh file holds one')
                    exit
                end if
                seen_at(s) = cur%line
            end if
            select case (cur%section)
            case ('$MeshFormat')
                call read_format(cur, error)
                seen_format = .true.
            case ('$PhysicalNames')
                call read_physical_names(cur, names, error)
            case ('$Entities')
                call read_entities(cur, entities, error)
            case ('$Nodes')
                call read_nodes(cur, xtag, min_tag, error)
                seen_nodes = .true.
            case ('$Elements')
                if (.not. seen_nodes) then
                    call fail(cur, error, '$Elements before $Nodes')
                    exit
                end if
                call read_elements(cur, xtag, min_tag, blocks, error)
                seen_elements = .true.
            case default
                call skip_section(cur, error)
            end select
            if (allocated(error)) exit
            if (s == 0) cycle
            call expect_end(cur, error)
            if (allocated(error)) exit
        end do
        close (cur%unit)
        if (allocated(error)) return
        cur%line = 0
        cur%section = ''
        if (.not. (seen_format .and. seen_nodes .and. seen_elements)) then
            call fail(cur, error, 'missing $MeshFormat, $Nodes or $Elements section')
            return
        end if
        call build_mesh(cur, entities, names, blocks, xtag, min_tag, mesh, error)
    end subroutine read_gmsh

    !> Error unless `path` can be read as a file: opening a directory succeeds, and reading it
    !> then looked like an empty file ('missing $MeshFormat ...'); reading its first byte fails
    !> with the system's reason ('Is a directory').
    subroutine check_readable(path, error)
        character(len=*), intent(in) :: path
        type(error_t), allocatable, intent(out) :: error
        integer :: unit, ios
        integer(i8) :: bytes
        character(len=1) :: first
        character(len=256) :: msg
        open (newunit=unit, file=path, access='stream', form='unformatted', status='old', &
              action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_input_error(error, path, 0, '', 'cannot open the mesh file: '//trim(msg))
            return
        end if
        inquire (unit=unit, size=bytes)
        if (bytes > 0) read (unit, iostat=ios, iomsg=msg) first
        close (unit)
        if (ios /= 0) call make_input_error(error, path, 0, '', 'cannot read the mesh file ('//trim(msg)// &
                                            '): give the path of a Gmsh .msh file')
    end subroutine check_readable

    !> Read the next line (any length) into text; eof at the end of the file.
    subroutine next_line(cur, text, eof, error)
        type(cursor_t), intent(inout) :: cur
        character(len=:), allocatable, intent(out) :: text
        logical, intent(out) :: eof
        type(error_t), allocatable, intent(out) :: error
        character(len=512) :: chunk
        integer :: ios, n
        character(len=256) :: msg
        text = ''
        eof = .false.
        cur%line = cur%line + 1
        do
            read (cur%unit, '(a)', advance='no', iostat=ios, iomsg=msg, size=n) chunk
            if (is_iostat_end(ios)) then
                eof = .true.
                return
            end if
            text = text//chunk(1:n)
            if (is_iostat_eor(ios)) exit
            if (ios /= 0) then
                call fail(cur, error, 'read error: '//trim(msg))
                return
            end if
        end do
        ! Tolerate files written on Windows (CR LF).
        n = len(text)
        if (n > 0) then
            if (text(n:n) == achar(13)) text = text(1:n - 1)
        end if
    end subroutine next_line

    !> Next line of the current section (an error at the end of the file).
    subroutine section_line(cur, text, error)
        type(cursor_t), intent(inout) :: cur
        character(len=:), allocatable, intent(out) :: text
        type(error_t), allocatable, intent(out) :: error
        logical :: eof
        call next_line(cur, text, eof, error)
        if (allocated(error)) return
        if (eof) call fail(cur, error, 'unexpected end of file (missing $End'//cur%section(2:)//')')
    end subroutine section_line

    !> Error at the cursor's line, naming the section.
    subroutine fail(cur, error, message)
        type(cursor_t), intent(in) :: cur
        type(error_t), allocatable, intent(out) :: error
        character(len=*), intent(in) :: message
        call make_input_error(error, cur%path, cur%line, cur%section, message)
    end subroutine fail

    !> A count read from the file must fit in it: `count` records of `lines` lines each, a line
    !> taking at least 2 bytes (a character and the end of line). Checked before the count
    !> sizes an array, which an absurd count (a typo, a damaged file) would make fail.
    subroutine check_count(cur, count, lines, what, error)
        type(cursor_t), intent(in) :: cur
        !> The count (integer(i8): a sum of counts may exceed the default integer range).
        integer(i8), intent(in) :: count
        integer, intent(in) :: lines
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        character(len=100) :: buf
        if (count < 0) then
            call fail(cur, error, 'negative number of '//what)
        else if (count > huge(0) .or. (cur%bytes >= 0 .and. count*lines*2 > cur%bytes)) then
            write (buf, '(i0,a,i0,a)') count, ' '//what//', more than the file holds (', cur%bytes, ' bytes)'
            call fail(cur, error, 'the header gives '//trim(buf))
        end if
    end subroutine check_count

    !> Integers of a line: exactly n of them, or at least n when at_least.
    subroutine read_ints(cur, text, n, values, error, at_least)
        type(cursor_t), intent(in) :: cur
        character(len=*), intent(in) :: text
        integer, intent(in) :: n
        integer, intent(out) :: values(n)
        type(error_t), allocatable, intent(out) :: error
        logical, intent(in), optional :: at_least
        integer :: ios
        character(len=32) :: buf
        read (text, *, iostat=ios) values
        if (ios /= 0) then
            write (buf, '(i0)') n
            call fail(cur, error, 'expected '//trim(buf)//' integers, found "'//trim(text)//'"')
            return
        end if
        if (present(at_least)) then
            if (at_least) return
        end if
        if (count_words(text) /= n) then
            write (buf, '(i0)') n
            call fail(cur, error, 'expected '//trim(buf)//' integers, found "'//trim(text)//'"')
        end if
    end subroutine read_ints

    !> Number of blank-separated words of a line.
    pure integer function count_words(text) result(n)
        character(len=*), intent(in) :: text
        integer :: i
        logical :: inside
        n = 0
        inside = .false.
        do i = 1, len(text)
            if (text(i:i) == ' ' .or. text(i:i) == achar(9)) then
                inside = .false.
            else if (.not. inside) then
                inside = .true.
                n = n + 1
            end if
        end do
    end function count_words

    !> $MeshFormat: version 4.1, ASCII.
    subroutine read_format(cur, error)
        type(cursor_t), intent(inout) :: cur
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        real(wp) :: version
        integer :: file_type, data_size, ios
        call section_line(cur, text, error)
        if (allocated(error)) return
        read (text, *, iostat=ios) version, file_type, data_size
        if (ios /= 0) then
            call fail(cur, error, 'expected "version file-type data-size", found "'//trim(text)//'"')
        else if (abs(version - 4.1_wp) > 1.0e-9_wp) then
            call fail(cur, error, 'only format 4.1 is read, found version "'//trim(text)// &
                      '" (write it with gmsh -format msh41)')
        else if (file_type /= 0) then
            call fail(cur, error, 'binary .msh files are not read: write ASCII (Mesh.Binary = 0)')
        end if
    end subroutine read_format

    !> The next line must be $End<section>.
    subroutine expect_end(cur, error)
        type(cursor_t), intent(inout) :: cur
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        call section_line(cur, text, error)
        if (allocated(error)) return
        if (trim(text) /= '$End'//cur%section(2:)) then
            call fail(cur, error, 'expected $End'//cur%section(2:)//', found "'//trim(text)//'"')
        end if
    end subroutine expect_end

    !> Skip an unknown section up to its $End line.
    subroutine skip_section(cur, error)
        type(cursor_t), intent(inout) :: cur
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        do
            call section_line(cur, text, error)
            if (allocated(error)) return
            if (trim(text) == '$End'//cur%section(2:)) return
        end do
    end subroutine skip_section

    !> $PhysicalNames: count, then lines 'dim tag "name"'.
    subroutine read_physical_names(cur, names, error)
        type(cursor_t), intent(inout) :: cur
        type(physical_name_t), allocatable, intent(out) :: names(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text, message
        integer :: n(1), k, j, dt(2), q1, q2
        call section_line(cur, text, error)
        if (allocated(error)) return
        call read_ints(cur, text, 1, n, error)
        if (allocated(error)) return
        call check_count(cur, int(n(1), i8), 1, 'physical names', error)
        if (allocated(error)) return
        allocate (names(n(1)))
        do k = 1, n(1)
            call section_line(cur, text, error)
            if (allocated(error)) return
            ! The name runs from the first double quote to the next: Gmsh writes a name
            ! without quotes inside, and nothing after it.
            q1 = index(text, '"')
            q2 = 0
            if (q1 > 0) q2 = index(text(q1 + 1:), '"')
            if (q1 == 0 .or. q2 <= 1) then
                call fail(cur, error, 'expected dim tag "name", found "'//trim(text)//'"')
                return
            end if
            q2 = q1 + q2
            if (verify(text(q2 + 1:), ' '//achar(9)) > 0) then
                if (index(text(q2 + 1:), '"') > 0) then
                    call fail(cur, error, 'a physical name cannot hold a double quote (Gmsh writes none), found '// &
                              trim(text(q1:))//' (expected dim tag "name")')
                else
                    call fail(cur, error, 'text after the name "'//text(q1 + 1:q2 - 1)//'": "'// &
                              strip(text(q2 + 1:))//'" (expected dim tag "name", nothing after it)')
                end if
                return
            end if
            call read_ints(cur, text(1:q1 - 1), 2, dt, error)
            if (allocated(error)) return
            names(k)%dim = dt(1)
            names(k)%tag = dt(2)
            names(k)%name = text(q1 + 1:q2 - 1)
            names(k)%line = cur%line
            message = set_name_problem(names(k)%name)
            if (len(message) > 0) then
                call fail(cur, error, 'physical group "'//names(k)%name//'" (dimension '//to_str(dt(1))// &
                          ', tag '//to_str(dt(2))//'): '//message//'; rename the group in the .geo file')
                return
            end if
            ! One name for groups of two dimensions (Physical Surface("a") and Physical
            ! Curve("a")) made one node set of both: `fix = a x` held the whole surface.
            do j = 1, k - 1
                if (names(j)%dim == names(k)%dim .or. .not. same_name(names(j)%name, names(k)%name)) cycle
                call fail(cur, error, 'physical group "'//names(k)%name//'" of dimension '//to_str(dt(1))// &
                          ' (tag '//to_str(dt(2))//') has the name of the group of dimension '// &
                          to_str(names(j)%dim)//' (tag '//to_str(names(j)%tag)//', line '//to_str(names(j)%line)// &
                          '): a set name stands for one group, and their nodes would make one node set (a fix '// &
                          'on it would hold both); give the groups different names in the .geo file')
                return
            end do
        end do
    end subroutine read_physical_names

    !> $Entities: points, curves, surfaces (and volumes, whose tags are ignored).
    subroutine read_entities(cur, entities, error)
        type(cursor_t), intent(inout) :: cur
        type(entity_t), allocatable, intent(out) :: entities(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        integer :: counts(4), dim, k, ios, tag, nphys, m
        real(wp) :: box(6)
        integer, allocatable :: phys(:)
        call section_line(cur, text, error)
        if (allocated(error)) return
        call read_ints(cur, text, 4, counts, error)
        if (allocated(error)) return
        if (any(counts < 0)) then
            call fail(cur, error, 'negative number of entities')
            return
        end if
        call check_count(cur, sum(int(counts, i8)), 1, 'entities', error)
        if (allocated(error)) return
        allocate (entities(sum(counts)))
        m = 0
        do dim = 0, 3
            do k = 1, counts(dim + 1)
                call section_line(cur, text, error)
                if (allocated(error)) return
                if (dim == 0) then
                    read (text, *, iostat=ios) tag, box(1:3), nphys
                else
                    read (text, *, iostat=ios) tag, box(1:6), nphys
                end if
                ! the tags follow on the line: no more of them than words
                if (ios == 0 .and. (nphys < 0 .or. nphys > count_words(text))) ios = 1
                if (ios == 0) then
                    allocate (phys(nphys))
                    if (dim == 0) then
                        read (text, *, iostat=ios) tag, box(1:3), nphys, phys
                    else
                        read (text, *, iostat=ios) tag, box(1:6), nphys, phys
                    end if
                end if
                if (ios /= 0) then
                    call fail(cur, error, 'malformed entity record "'//trim(text)//'"')
                    return
                end if
                m = m + 1
                entities(m)%dim = dim
                entities(m)%tag = tag
                call move_alloc(phys, entities(m)%physical)
                entities(m)%physical = abs(entities(m)%physical)
            end do
        end do
    end subroutine read_entities

    !> $Nodes: blocks of tags then coordinates; xtag(:, tag - min_tag + 1) = (x, y), -huge when
    !> the tag is unused. The header's node count must be the blocks' total, a tag must appear
    !> once, and coordinates must be finite numbers. The mesh is planar in (x, y): every node
    !> has the z of the first within 1e-9 of the extent in (x, y) (z is dropped; a mesh drawn
    !> in another plane, or a node moved out of the plane, would be silently flattened).
    subroutine read_nodes(cur, xtag, min_tag, error)
        type(cursor_t), intent(inout) :: cur
        real(wp), allocatable, intent(out) :: xtag(:, :)
        integer, intent(out) :: min_tag
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        type(string_t), allocatable :: words(:)
        type(cursor_t) :: header
        integer :: head(4), bh(4), b, k, i, total, n_words
        integer, allocatable :: tags(:)
        real(wp) :: xyz(3), value, z0, z_off, lo(2), hi(2)
        type(cursor_t) :: off_plane
        logical :: ok, have_z0
        character(len=64) :: buf
        z_off = 0.0_wp
        z0 = 0.0_wp
        have_z0 = .false.
        lo = huge(1.0_wp)
        hi = -huge(1.0_wp)
        call section_line(cur, text, error)
        if (allocated(error)) return
        call read_ints(cur, text, 4, head, error)
        if (allocated(error)) return
        header = cur
        min_tag = head(3)
        call check_count(cur, int(head(1), i8), 1, 'node blocks', error)
        if (allocated(error)) return
        call check_count(cur, int(head(2), i8), 2, 'nodes', error)
        if (allocated(error)) return
        if (head(2) > 0 .and. (head(3) < 1 .or. head(4) < head(3))) then
            call fail(cur, error, 'invalid node tag range in "'//trim(text)//'"')
            return
        end if
        if (int(head(4), i8) - head(3) + 1 > max(int(min_tag_span, i8), int(tags_per_node, i8)*head(2))) then
            write (buf, '(a,i0,a,i0,a,i0,a)') 'node tags span ', head(3), ' to ', head(4), ' for ', head(2), &
                ' nodes'
            call fail(cur, error, trim(buf)//': number the nodes contiguously (Gmsh does by default: '// &
                      'Mesh.Renumber = 1)')
            return
        end if
        allocate (xtag(2, max(head(4) - head(3) + 1, 0)), source=-huge(1.0_wp))
        total = 0
        do b = 1, head(1)
            call section_line(cur, text, error)
            if (allocated(error)) return
            call read_ints(cur, text, 4, bh, error)
            if (allocated(error)) return
            call check_count(cur, int(bh(4), i8), 2, 'nodes in the block', error)
            if (allocated(error)) return
            ! 'entityDim entityTag parametric numNodesInBlock': a parametric block (1) gives, after
            ! x y z, entityDim parametric coordinates, which are not used.
            if (bh(3) /= 0 .and. bh(3) /= 1) then
                call fail(cur, error, 'the parametric flag of a node block is 0 or 1, found "'//trim(text)//'"')
                return
            end if
            n_words = 3 + merge(bh(1), 0, bh(3) == 1)
            total = total + bh(4)
            allocate (tags(bh(4)))
            do k = 1, bh(4)
                call section_line(cur, text, error)
                if (allocated(error)) return
                call read_ints(cur, text, 1, tags(k:k), error)
                if (allocated(error)) return
                if (tags(k) < head(3) .or. tags(k) > head(4)) then
                    call fail(cur, error, 'node tag outside the range given in the $Nodes header')
                    return
                end if
            end do
            do k = 1, bh(4)
                call section_line(cur, text, error)
                if (allocated(error)) return
                ! Word by word: a list-directed read takes 'nan' and 'inf', and overflows on 1e999.
                ! All 3 coordinates, exactly: a short line left the missing ones from the node before.
                call split_words(text, words)
                ok = size(words) == n_words
                if (ok) then
                    do i = 1, size(words)
                        call parse_real(words(i)%s, value, ok)
                        if (.not. ok) exit
                        if (i <= 3) xyz(i) = value
                    end do
                end if
                if (.not. ok) then
                    if (n_words == 3) then
                        call fail(cur, error, 'expected node coordinates "x y z" (finite numbers), found "'// &
                                  trim(text)//'"')
                    else
                        write (buf, '(i0)') n_words - 3
                        call fail(cur, error, 'expected node coordinates "x y z" and '//trim(buf)//' parametric '// &
                                  'coordinates (finite numbers), found "'//trim(text)//'"')
                    end if
                    return
                end if
                if (xtag(1, tags(k) - min_tag + 1) /= -huge(1.0_wp)) then
                    write (buf, '(i0)') tags(k)
                    call fail(cur, error, 'node '//trim(buf)//' is defined twice')
                    return
                end if
                xtag(:, tags(k) - min_tag + 1) = xyz(1:2)
                lo = min(lo, xyz(1:2))
                hi = max(hi, xyz(1:2))
                if (.not. have_z0) z0 = xyz(3)
                have_z0 = .true.
                if (abs(xyz(3) - z0) > z_off) then
                    z_off = abs(xyz(3) - z0)
                    off_plane = cur
                end if
            end do
            deallocate (tags)
        end do
        if (total /= head(2)) then
            write (buf, '(i0,a,i0)') head(2), ' nodes, its blocks hold ', total
            call fail(header, error, 'the header gives '//trim(buf))
            return
        end if
        if (z_off > 1.0e-9_wp*hypot(hi(1) - lo(1), hi(2) - lo(2))) then
            call fail(off_plane, error, 'this node lies off the plane z = '//to_str(z0)// &
                      ' of the first node (by '//to_str(z_off)//'): a 2D mesh lies in a plane parallel '// &
                      'to (x, y), its z is dropped')
        end if
    end subroutine read_nodes

    !> Number of nodes of a Gmsh element type this reader accepts (0 otherwise): points, lines
    !> and the types of the registered element kinds.
    pure integer function type_nodes(type)
        integer, intent(in) :: type
        select case (type)
        case (15)
            type_nodes = 1
        case (1)
            type_nodes = 2
        case default
            type_nodes = kind_node_count(kind_of_gmsh_type(type))
        end select
    end function type_nodes

    !> $Elements: header 'blocks elements min_tag max_tag', then blocks 'dim entity type count'
    !> and 'tag node...' lines. As for $Nodes, the header's element count must be the blocks'
    !> total and every tag lie in its range; a tag must appear once, and no two line, triangle
    !> or quadrangle elements may have the same nodes.
    subroutine read_elements(cur, xtag, min_tag, blocks, error)
        type(cursor_t), intent(inout) :: cur
        real(wp), intent(in) :: xtag(:, :)
        integer, intent(in) :: min_tag
        type(block_t), allocatable, intent(out) :: blocks(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        type(cursor_t) :: header
        integer :: head(4), bh(4), b, k, nn
        integer(i8) :: total
        integer, allocatable :: values(:)
        character(len=64) :: buf
        call section_line(cur, text, error)
        if (allocated(error)) return
        call read_ints(cur, text, 4, head, error)
        if (allocated(error)) return
        header = cur
        call check_count(cur, int(head(1), i8), 1, 'element blocks', error)
        if (allocated(error)) return
        call check_count(cur, int(head(2), i8), 1, 'elements', error)
        if (allocated(error)) return
        if (head(2) > 0 .and. (head(3) < 1 .or. head(4) < head(3))) then
            call fail(cur, error, 'invalid element tag range in "'//trim(text)//'"')
            return
        end if
        allocate (blocks(head(1)))
        total = 0
        do b = 1, head(1)
            call section_line(cur, text, error)
            if (allocated(error)) return
            call read_ints(cur, text, 4, bh, error)
            if (allocated(error)) return
            nn = type_nodes(bh(3))
            if (nn == 0) then
                write (buf, '(i0)') bh(3)
                call fail(cur, error, 'element type '//trim(buf)//' is not supported (only 2-node lines, '// &
                          '3-node triangles, 4-node quadrangles and points: mesh in 2D with Mesh.ElementOrder = 1)')
                return
            end if
            call check_count(cur, int(bh(4), i8), 1, 'elements in the block', error)
            if (allocated(error)) return
            total = total + bh(4)
            associate (blk => blocks(b))
                blk%dim = bh(1)
                blk%tag = bh(2)
                blk%type = bh(3)
                blk%line = cur%line
                allocate (blk%nodes(nn, bh(4)), blk%lines(bh(4)), blk%tags(bh(4)), values(nn + 1))
                do k = 1, bh(4)
                    call section_line(cur, text, error)
                    if (allocated(error)) return
                    blk%lines(k) = cur%line
                    call read_ints(cur, text, nn + 1, values, error)
                    if (allocated(error)) return
                    if (values(1) < head(3) .or. values(1) > head(4)) then
                        call fail(cur, error, 'element tag outside the range given in the $Elements header')
                        return
                    end if
                    blk%tags(k) = values(1)
                    blk%nodes(:, k) = values(2:)
                    call check_tags(values(2:))
                    if (allocated(error)) return
                end do
                deallocate (values)
            end associate
        end do
        if (total /= head(2)) then
            write (buf, '(i0,a,i0)') head(2), ' elements, its blocks hold ', total
            call fail(header, error, 'the header gives '//trim(buf))
            return
        end if
        call check_unique_tags(cur, blocks, error)
        if (allocated(error)) return
        call check_distinct_nodes(cur, blocks, error)

    contains

        !> Every node of an element must be a node of $Nodes.
        subroutine check_tags(tags)
            integer, intent(in) :: tags(:)
            integer :: i
            character(len=32) :: tb
            do i = 1, size(tags)
                if (tags(i) >= min_tag .and. tags(i) <= min_tag + size(xtag, 2) - 1) then
                    if (xtag(1, tags(i) - min_tag + 1) /= -huge(1.0_wp)) cycle
                end if
                write (tb, '(i0)') tags(i)
                call fail(cur, error, 'node '//trim(tb)//' is not defined in $Nodes')
                return
            end do
        end subroutine check_tags
    end subroutine read_elements

    !> An element tag may appear once (over all blocks); the error is at the second occurrence
    !> that comes first in the file.
    subroutine check_unique_tags(cur, blocks, error)
        type(cursor_t), intent(in) :: cur
        type(block_t), intent(in) :: blocks(:)
        type(error_t), allocatable, intent(out) :: error
        integer(i8), allocatable :: keys(:)
        integer, allocatable :: lines(:), order(:)
        integer :: b, k, n, at, first
        character(len=64) :: buf
        allocate (keys(sum([(size(blocks(b)%tags), b=1, size(blocks))])))
        allocate (lines(size(keys)))
        n = 0
        do b = 1, size(blocks)
            keys(n + 1:n + size(blocks(b)%tags)) = blocks(b)%tags
            lines(n + 1:n + size(blocks(b)%tags)) = blocks(b)%lines
            n = n + size(blocks(b)%tags)
        end do
        order = sort_index(keys)
        ! sort_index is stable: of two equal tags, the earlier in the file comes first.
        call earliest_repeat(order, [.false., (keys(order(k)) == keys(order(k - 1)), k=2, size(order))], lines, &
                             at, first)
        if (at == 0) return
        write (buf, '(i0,a,i0,a)') keys(at), ' is defined twice (first on line ', lines(first), ')'
        call make_input_error(error, cur%path, lines(at), '$Elements', 'element '//trim(buf))
    end subroutine check_unique_tags

    !> No two elements of dimension 1 or 2 may have the same set of nodes (whatever their order):
    !> an element listed twice under two tags counts its stiffness and mass, or its share of an
    !> edge load, twice. The nodes of each element, sorted in decreasing order and padded with
    !> 0 to 4 (a line has 2, a triangle 3, a quadrangle 4: different kinds never compare
    !> equal), are packed two by two in 64-bit keys (tags < 2^31) and sorted lexicographically
    !> by two stable passes.
    subroutine check_distinct_nodes(cur, blocks, error)
        type(cursor_t), intent(in) :: cur
        type(block_t), intent(in) :: blocks(:)
        type(error_t), allocatable, intent(out) :: error
        integer(i8), allocatable :: high(:), low(:)
        integer, allocatable :: lines(:), tags(:), order(:)
        integer :: b, k, n, at, first, sorted(4)
        character(len=96) :: buf
        n = 0
        do b = 1, size(blocks)
            if (blocks(b)%type /= 1 .and. kind_of_gmsh_type(blocks(b)%type) == 0) cycle
            n = n + size(blocks(b)%tags)
        end do
        allocate (high(n), low(n), lines(n), tags(n))
        n = 0
        do b = 1, size(blocks)
            if (blocks(b)%type /= 1 .and. kind_of_gmsh_type(blocks(b)%type) == 0) cycle
            do k = 1, size(blocks(b)%tags)
                n = n + 1
                sorted = 0
                sorted(1:size(blocks(b)%nodes, 1)) = blocks(b)%nodes(:, k)
                call sort_decreasing(sorted)
                high(n) = int(sorted(1), i8)*2_i8**31 + sorted(2)
                low(n) = int(sorted(3), i8)*2_i8**31 + sorted(4)
                lines(n) = blocks(b)%lines(k)
                tags(n) = blocks(b)%tags(k)
            end do
        end do
        order = sort_index(low)
        order = order(sort_index(high(order)))
        call earliest_repeat(order, [.false., (high(order(k)) == high(order(k - 1)) .and. &
                                               low(order(k)) == low(order(k - 1)), k=2, n)], lines, at, first)
        if (at == 0) return
        write (buf, '(a,i0,a,i0,a,i0,a)') 'element ', tags(at), ' has the same nodes as element ', tags(first), &
            ' (line ', lines(first), ')'
        call make_input_error(error, cur%path, lines(at), '$Elements', trim(buf)//': an element may be listed once')

    contains

        !> Sort 4 node tags (< 2^31: exact as reals) in decreasing order.
        pure subroutine sort_decreasing(a)
            integer, intent(inout) :: a(4)
            real(wp) :: r(4)
            r = real(a, wp)
            call sort_in_place(r)
            a = nint(r(4:1:-1))
        end subroutine sort_decreasing
    end subroutine check_distinct_nodes

    !> Of the entries in sorted order that repeat the one before them (repeat(k) for order(k)),
    !> the one on the earliest line: at = that entry, first = the entry it repeats (at = 0
    !> when nothing repeats).
    pure subroutine earliest_repeat(order, repeat, lines, at, first)
        integer, intent(in) :: order(:)
        logical, intent(in) :: repeat(:)
        integer, intent(in) :: lines(:)
        integer, intent(out) :: at, first
        integer :: k
        at = 0
        first = 0
        do k = 2, size(order)
            if (.not. repeat(k)) cycle
            if (at > 0) then
                if (lines(order(k)) >= lines(at)) cycle
            end if
            at = order(k)
            first = order(k - 1)
        end do
    end subroutine earliest_repeat

    !> Name of a physical group.
    pure function group_name(names, dim, tag) result(name)
        type(physical_name_t), intent(in) :: names(:)
        integer, intent(in) :: dim, tag
        character(len=:), allocatable :: name
        character(len=32) :: buf
        integer :: k
        do k = 1, size(names)
            if (names(k)%dim == dim .and. names(k)%tag == tag) then
                name = names(k)%name
                return
            end if
        end do
        write (buf, '(a,i0,a,i0)') 'physical_', dim, '_', tag
        name = trim(buf)
    end function group_name

    !> Physical tags of entity (dim, tag) (empty when not listed).
    pure function entity_physical(entities, dim, tag) result(phys)
        type(entity_t), intent(in) :: entities(:)
        integer, intent(in) :: dim, tag
        integer, allocatable :: phys(:)
        integer :: k
        do k = 1, size(entities)
            if (entities(k)%dim == dim .and. entities(k)%tag == tag) then
                phys = entities(k)%physical
                return
            end if
        end do
        allocate (phys(0))
    end function entity_physical

    !> Assemble the mesh from the sections read.
    subroutine build_mesh(cur, entities, names, blocks, xtag, min_tag, mesh, error)
        type(cursor_t), intent(in) :: cur
        type(entity_t), intent(in) :: entities(:)
        type(physical_name_t), intent(in) :: names(:)
        type(block_t), intent(inout) :: blocks(:)
        real(wp), intent(in) :: xtag(:, :)
        integer, intent(in) :: min_tag
        type(mesh2d_t), intent(out) :: mesh
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: index_of_tag(:), phys(:), local(:, :)
        integer :: b, ne, e, k, p, nnodes, failed(2), kind
        character(len=64) :: buf
        character(len=:), allocatable :: name
        ! Map tags to compact node indices, keeping the nodes of triangles and quadrangles.
        allocate (index_of_tag(size(xtag, 2)), source=0)
        ne = 0
        do b = 1, size(blocks)
            if (kind_of_gmsh_type(blocks(b)%type) > 0) then
                index_of_tag(reshape(blocks(b)%nodes, [size(blocks(b)%nodes)]) - min_tag + 1) = 1
                ne = ne + size(blocks(b)%nodes, 2)
            end if
        end do
        if (ne == 0) then
            ! Gmsh saves only the elements of its physical groups when there is any: groups
            ! of curves or points alone leave the surfaces' elements out of a 2D mesh.
            if ((size(names) > 0 .or. any([(size(entities(k)%physical) > 0, k=1, size(entities))])) .and. &
                .not. (any(names%dim == 2) .or. &
                       any([(entities(k)%dim == 2 .and. size(entities(k)%physical) > 0, k=1, size(entities))]))) then
                call fail(cur, error, 'the mesh has no triangle or quadrangle: the file has physical groups '// &
                          'but none of dimension 2, and Gmsh then saves only the elements of the groups (the '// &
                          'lines and points); add a Physical Surface holding the surfaces to the .geo file '// &
                          '(or mesh with gmsh -2 -setnumber Mesh.SaveAll 1)')
            else
                call fail(cur, error, 'the mesh has no triangle or quadrangle (mesh it in 2D: gmsh -2)')
            end if
            return
        end if
        nnodes = 0
        do k = 1, size(index_of_tag)
            if (index_of_tag(k) == 0) cycle
            nnodes = nnodes + 1
            index_of_tag(k) = nnodes
        end do
        allocate (mesh%x(2, nnodes))
        do k = 1, size(index_of_tag)
            if (index_of_tag(k) == 0) cycle
            mesh%x(:, index_of_tag(k)) = xtag(:, k)
        end do
        allocate (mesh%kind(ne), mesh%connectivity(max_node_count(), ne), mesh%element_tag(ne), mesh%element_line(ne), &
                  source=0)
        mesh%file = cur%path
        e = 0
        do b = 1, size(blocks)
            kind = kind_of_gmsh_type(blocks(b)%type)
            if (kind == 0) cycle
            blocks(b)%first = e + 1
            do k = 1, size(blocks(b)%nodes, 2)
                e = e + 1
                mesh%kind(e) = kind
                mesh%element_tag(e) = blocks(b)%tags(k)
                mesh%element_line(e) = blocks(b)%lines(k)
                mesh%connectivity(1:size(blocks(b)%nodes, 1), e) = index_of_tag(blocks(b)%nodes(:, k) - min_tag + 1)
            end do
        end do
        call mesh%orient_elements()
        allocate (mesh%declared(size(names)))
        do k = 1, size(names)
            mesh%declared(k)%name = names(k)%name
            mesh%declared(k)%dim = names(k)%dim
        end do
        ! Named sets from the physical groups of each block's entity.
        do b = 1, size(blocks)
            phys = entity_physical(entities, blocks(b)%dim, blocks(b)%tag)
            if (size(phys) == 0) cycle
            local = reshape(index_of_tag(reshape(blocks(b)%nodes, [size(blocks(b)%nodes)]) - min_tag + 1), &
                            shape(blocks(b)%nodes))
            if (any(local == 0)) then
                write (buf, '(i0,a,i0)') blocks(b)%dim, ', entity ', blocks(b)%tag
                call make_input_error(error, cur%path, blocks(b)%line, '$Elements', 'physical group '''// &
                                      group_name(names, blocks(b)%dim, phys(1))//''' (dimension '//trim(buf)// &
                                      ') has nodes on no triangle or quadrangle')
                return
            end if
            do p = 1, size(phys)
                name = group_name(names, blocks(b)%dim, phys(p))
                call mesh%add_node_set(name, reshape(local, [size(local)]))
                if (blocks(b)%type == 1) call mesh%add_edge_set(name, local)
                if (blocks(b)%first > 0) then
                    call mesh%add_element_set(name, [(blocks(b)%first + k - 1, k=1, size(local, 2))])
                end if
            end do
        end do
        ! A mesh without physical groups has no named sets: empty lists, not unallocated ones.
        if (.not. allocated(mesh%node_sets)) allocate (mesh%node_sets(0))
        if (.not. allocated(mesh%element_sets)) allocate (mesh%element_sets(0))
        if (.not. allocated(mesh%edge_sets)) allocate (mesh%edge_sets(0))
        call mesh%orient_edges(error, failed)
        if (allocated(error)) then
            call locate_edge(failed, b, k)
            if (b > 0) then
                write (buf, '(i0,a,i0)') blocks(b)%nodes(1, k), ' and ', blocks(b)%nodes(2, k)
                deallocate (error)
                call make_input_error(error, cur%path, blocks(b)%lines(k), '$Elements', 'the line element '// &
                                      'of physical group '''//mesh%edge_sets(failed(1))%name//''' between '// &
                                      'nodes '//trim(buf)//' is not a side of any triangle or quadrangle')
            else
                error%message = cur%path//': '//error%message
            end if
        end if

    contains

        !> Block bb and element kk in it of edge failed(2) of edge set failed(1) (the sets gather
        !> the line blocks of their physical group in block order); bb = 0 when not found.
        subroutine locate_edge(failed, bb, kk)
            integer, intent(in) :: failed(2)
            integer, intent(out) :: bb, kk
            integer :: q
            kk = failed(2)
            do bb = 1, size(blocks)
                if (blocks(bb)%type /= 1) cycle
                phys = entity_physical(entities, blocks(bb)%dim, blocks(bb)%tag)
                do q = 1, size(phys)
                    if (.not. same_name(group_name(names, blocks(bb)%dim, phys(q)), mesh%edge_sets(failed(1))%name)) cycle
                    if (kk <= size(blocks(bb)%lines)) return
                    kk = kk - size(blocks(bb)%lines)
                    exit
                end do
            end do
            bb = 0
        end subroutine locate_edge
    end subroutine build_mesh
end module fem_gmsh_reader
