!> From a validated deck to the frame's configuration `fem_beam_config::beam_config_t`: its
!> sections, nodes and elements, supports, loads (the time functions they name read by
!> driver_config_timefunc), gravity, mass and damping, and its initial state ([initial]). The
!> deck reader has checked each line on its own; here come the checks across lines:
!> references to node, section and function ids, duplicate ids, zero-length or duplicate
!> elements, loads and initial conditions on fixed DOFs, an empty model. Each error names the
!> deck file, the line and the keyword concerned.
!>
!> Nodes come from `node` records and `line` generators. A `line` creates nodes
!> first_node..first_node+elements equally spaced from (x1, y1) to (x2, y2) and the elements
!> between them; a node id that already exists is reused when its coordinates coincide
!> (|dx|, |dy| <= 1e-9 line length), otherwise it is an error. Node ids are mapped to
!> indices 1..n in increasing id order (`beam%node_id(i)` is the deck id of node i).
module driver_config_beam
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_constants, only: deg_to_rad
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, to_str
    use core_sort, only: sort_index
    use fem_beam_config, only: beam_config_t, beam_section_t, dof_u, dof_w, dof_theta, beam_element_load_t, &
                               load_x, load_y, load_axial, load_transverse
    use fem_beam_element, only: element_stiffness, element_mass_consistent, element_mass_lumped
    use fem_mass_scheme, only: make_mass_scheme
    use io_deck, only: deck_t, deck_entry_t
    use driver_config_timefunc, only: build_time_functions
    implicit none
    private
    public :: build_beam_config, build_initial, repeated_dof

    !> Relative tolerance for coincident nodes and zero lengths (times a length).
    real(wp), parameter :: coincidence = 1.0e-9_wp

    !> A node before numbering: deck id, position, where it was defined.
    type :: node_candidate_t
        !> Deck id.
        integer :: id = 0
        !> Position [m].
        real(wp) :: x = 0.0_wp, y = 0.0_wp
        !> Coincidence tolerance [m] (0 for an explicit node).
        real(wp) :: tol = 0.0_wp
        !> Deck line.
        integer :: line = 0
        !> Created by a `line` generator (else a `node` record).
        logical :: generated = .false.
    end type node_candidate_t

    !> An element before numbering: deck ids of its nodes and section, where it was defined.
    type :: element_candidate_t
        !> Element id (explicit elements) or 0 (generated).
        integer :: id = 0
        !> Deck ids of the end nodes.
        integer :: node(2) = 0
        !> Deck id of the section.
        integer :: section = 0
        !> Deck line.
        integer :: line = 0
        !> Created by a `line` generator (else an `element` record).
        logical :: generated = .false.
    end type element_candidate_t

contains

    !> Fill the beam configuration from a validated deck, with cross checks: sections, mesh,
    !> time functions, supports, loads, gravity, mass and damping (not the initial state:
    !> `build_initial`).
    subroutine build_beam_config(deck, beam, fix_line, error)
        !> Deck read by io_deck::read_deck with the MULTICOR schema.
        type(deck_t), intent(in) :: deck
        !> Beam model configuration.
        type(beam_config_t), intent(out) :: beam
        !> Line of the `fix` record fixing each DOF (3, n_nodes; 0 if free).
        integer, allocatable, intent(out) :: fix_line(:, :)
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: section_ids(:), function_ids(:)
        call build_sections(deck, beam, section_ids, error)
        if (allocated(error)) return
        call build_mesh(deck, section_ids, beam, error)
        if (allocated(error)) return
        call build_time_functions(deck, beam%functions, function_ids, error)
        if (allocated(error)) return
        call build_supports(deck, beam, fix_line, error)
        if (allocated(error)) return
        call build_loads(deck, function_ids, fix_line, beam, error)
        if (allocated(error)) return
        call build_distributed_loads(deck, function_ids, beam, error)
        if (allocated(error)) return
        beam%gravity = [deck%get_real('beam', 'gravity', 'gx'), deck%get_real('beam', 'gravity', 'gy')]
        call make_mass_scheme(deck%get_word('beam', 'mass'), beam%mass_scheme, error)
        if (allocated(error)) return
        beam%rayleigh_a0 = deck%get_real('beam', 'rayleigh', 'a0')
        beam%rayleigh_a1 = deck%get_real('beam', 'rayleigh', 'a1')
    end subroutine build_beam_config

    !> Sections, with unique ids.
    subroutine build_sections(deck, beam, ids, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Beam configuration (sections filled).
        type(beam_config_t), intent(inout) :: beam
        !> Deck id of each section.
        integer, allocatable, intent(out) :: ids(:)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        type(deck_entry_t) :: e
        integer :: i, n, j
        allocate (list, source=deck%records('beam', 'section'))
        n = size(list)
        allocate (beam%sections(n), ids(n))
        do i = 1, n
            e = list(i)
            ids(i) = e%int('id')
            j = findloc(ids(:i - 1), ids(i), dim=1)
            if (j > 0) then
                call make_input_error(error, deck%file, e%line, 'section', &
                                      'duplicate section id '// &
                                      to_str(ids(i))//': already defined on line '//to_str(list(j)%line))
                return
            end if
            beam%sections(i)%young = e%real('young')
            beam%sections(i)%density = e%real('density')
            beam%sections(i)%area = e%real('area')
            beam%sections(i)%inertia = e%real('inertia')
        end do
    end subroutine build_sections

    !> Nodes and elements from `node`, `line` and `element` records (in file order).
    subroutine build_mesh(deck, section_ids, beam, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Deck ids of the sections.
        integer, intent(in) :: section_ids(:)
        !> Beam configuration (x, y, node_id, conn, elem_section filled).
        type(beam_config_t), intent(inout) :: beam
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(node_candidate_t), allocatable :: nodes(:)
        type(element_candidate_t), allocatable :: elements(:)
        integer, allocatable :: def_line(:)
        integer :: n_nodes, n_elements
        call collect_candidates(deck, nodes, n_nodes, elements, n_elements, error)
        if (allocated(error)) return
        call merge_nodes(deck, nodes(:n_nodes), beam, def_line, error)
        if (allocated(error)) return
        if (n_elements == 0) then
            call make_input_error(error, deck%file, 0, '', 'the model has no element: '// &
                                  'add [beam] line or element records')
            return
        end if
        call resolve_elements(deck, elements(:n_elements), section_ids, def_line, beam, error)
    end subroutine build_mesh

    !> Walk the [beam] entries in file order; list node and element candidates.
    subroutine collect_candidates(deck, nodes, n_nodes, elements, n_elements, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Node candidates (first n_nodes used).
        type(node_candidate_t), allocatable, intent(out) :: nodes(:)
        !> Number of node candidates.
        integer, intent(out) :: n_nodes
        !> Element candidates (first n_elements used).
        type(element_candidate_t), allocatable, intent(out) :: elements(:)
        !> Number of element candidates.
        integer, intent(out) :: n_elements
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        integer :: i, j, ne, first, stat
        integer(i8) :: total_nodes, total_elements
        real(wp) :: x1, y1, x2, y2, length, size_model
        ! Sizes first, so that arrays are allocated once.
        total_nodes = 0
        total_elements = 0
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                if (e%section /= 'beam') cycle
                select case (e%keyword)
                case ('node')
                    total_nodes = total_nodes + 1
                case ('element')
                    total_elements = total_elements + 1
                case ('line', 'polar_line')
                    if (e%int('first_node') > huge(0) - e%int('elements')) then
                        call make_input_error(error, deck%file, e%line, e%keyword, 'node ids '// &
                                              e%word('first_node')//' + '//e%word('elements')//' exceed the largest integer')
                        return
                    end if
                    total_nodes = total_nodes + e%int('elements') + 1
                    total_elements = total_elements + e%int('elements')
                end select
            end associate
        end do
        stat = 1
        if (max(total_nodes, total_elements) < huge(0)) then
            allocate (nodes(total_nodes), elements(total_elements), stat=stat)
        end if
        if (stat /= 0) then
            call make_input_error(error, deck%file, 0, '', 'the model is too large: '// &
                                  'cannot hold its nodes and elements in memory')
            return
        end if
        size_model = model_size(deck)
        n_nodes = 0
        n_elements = 0
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                if (e%section /= 'beam') cycle
                select case (e%keyword)
                case ('node')
                    n_nodes = n_nodes + 1
                    nodes(n_nodes) = node_candidate_t(e%int('id'), e%real('x'), e%real('y'), 0.0_wp, &
                                                      e%line, .false.)
                case ('element')
                    n_elements = n_elements + 1
                    elements(n_elements) = element_candidate_t(e%int('id'), [e%int('node1'), e%int('node2')], &
                                                               e%int('section'), e%line, .false.)
                case ('line', 'polar_line')
                    first = e%int('first_node')
                    x1 = e%real('x1')
                    y1 = e%real('y1')
                    call line_end(e, x2, y2)
                    ne = e%int('elements')
                    length = hypot(x2 - x1, y2 - y1)
                    if (length <= coincidence*size_model) then
                        call make_input_error(error, deck%file, e%line, e%keyword, &
                                              'zero-length line: (x1, y1) and (x2, y2) coincide')
                        return
                    end if
                    do j = 0, ne
                        n_nodes = n_nodes + 1
                        nodes(n_nodes) = node_candidate_t(first + j, &
                                                          x1 + (x2 - x1)*real(j, wp)/real(ne, wp), &
                                                          y1 + (y2 - y1)*real(j, wp)/real(ne, wp), &
                                                          coincidence*length, e%line, .true.)
                    end do
                    do j = 1, ne
                        n_elements = n_elements + 1
                        elements(n_elements) = element_candidate_t(0, [first + j - 1, first + j], &
                                                                   e%int('section'), e%line, .true.)
                    end do
                end select
            end associate
        end do
    end subroutine collect_candidates

    !> End (x2, y2) of a `line` record, or of a `polar_line` record (first_node x1 y1 length
    !> angle_deg elements section): (x1, y1) + length (cos angle, sin angle).
    subroutine line_end(e, x2, y2)
        !> The record.
        type(deck_entry_t), intent(in) :: e
        !> End point [m].
        real(wp), intent(out) :: x2, y2
        real(wp) :: angle
        if (e%keyword == 'polar_line') then
            angle = e%real('angle_deg')*deg_to_rad
            x2 = e%real('x1') + e%real('length')*cos(angle)
            y2 = e%real('y1') + e%real('length')*sin(angle)
        else
            x2 = e%real('x2')
            y2 = e%real('y2')
        end if
    end subroutine line_end

    !> Keyword of the [beam] record on a deck line ('node' when none is found).
    function beam_keyword_at(deck, line) result(keyword)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Deck line.
        integer, intent(in) :: line
        character(len=:), allocatable :: keyword
        integer :: i
        keyword = 'node'
        do i = 1, size(deck%entries)
            if (deck%entries(i)%section /= 'beam' .or. deck%entries(i)%line /= line) cycle
            keyword = deck%entries(i)%keyword
            return
        end do
    end function beam_keyword_at

    !> Size of the model: diagonal of the bounding box of all nodes and line ends [m].
    function model_size(deck) result(size_model)
        !> The deck.
        type(deck_t), intent(in) :: deck
        real(wp) :: size_model
        real(wp) :: lo(2), hi(2), x2, y2
        integer :: i
        lo = huge(1.0_wp)
        hi = -huge(1.0_wp)
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                if (e%section /= 'beam') cycle
                select case (e%keyword)
                case ('node')
                    lo = min(lo, [e%real('x'), e%real('y')])
                    hi = max(hi, [e%real('x'), e%real('y')])
                case ('line', 'polar_line')
                    call line_end(e, x2, y2)
                    lo = min(lo, [e%real('x1'), e%real('y1')], [x2, y2])
                    hi = max(hi, [e%real('x1'), e%real('y1')], [x2, y2])
                end select
            end associate
        end do
        size_model = 0.0_wp
        if (all(hi >= lo)) size_model = hypot(hi(1) - lo(1), hi(2) - lo(2))
    end function model_size

    !> Merge candidates with the same id (generated nodes reuse coincident existing ones),
    !> number the nodes in increasing id order, fill x, y and node_id.
    subroutine merge_nodes(deck, nodes, beam, def_line, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Node candidates in file order.
        type(node_candidate_t), intent(in) :: nodes(:)
        !> Beam configuration (x, y, node_id filled).
        type(beam_config_t), intent(inout) :: beam
        !> Deck line defining each node.
        integer, allocatable, intent(out) :: def_line(:)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        integer :: order(size(nodes))
        integer :: i, n, ref
        order = sort_index([(int(nodes(i)%id, i8), i=1, size(nodes))])
        allocate (beam%x(size(nodes)), beam%y(size(nodes)), beam%node_id(size(nodes)))
        allocate (def_line(size(nodes)))
        n = 0
        ref = 0
        do i = 1, size(nodes)
            associate (c => nodes(order(i)))
                if (n > 0) then
                    if (c%id == beam%node_id(n)) then
                        call check_same_node(nodes(ref), c)
                        if (allocated(error)) return
                        cycle
                    end if
                end if
                n = n + 1
                ref = order(i)
                beam%node_id(n) = c%id
                beam%x(n) = c%x
                beam%y(n) = c%y
                def_line(n) = c%line
            end associate
        end do
        beam%x = beam%x(:n)
        beam%y = beam%y(:n)
        beam%node_id = beam%node_id(:n)
        def_line = def_line(:n)

    contains

        !> A second definition of a node id: an error unless a generator meets a coincident
        !> existing node.
        subroutine check_same_node(first, again)
            type(node_candidate_t), intent(in) :: first, again
            character(len=:), allocatable :: keyword
            keyword = beam_keyword_at(deck, again%line)
            if (.not. again%generated) then
                call make_input_error(error, deck%file, again%line, keyword, &
                                      'duplicate node id '// &
                                      to_str(again%id)//': already defined on line '// &
                                      to_str(first%line))
            else if (abs(again%x - first%x) > again%tol .or. &
                     abs(again%y - first%y) > again%tol) then
                call make_input_error(error, deck%file, again%line, keyword, 'node '// &
                                      to_str(again%id)//' would be at ('//to_str(again%x)//', '// &
                                      to_str(again%y)//') but already exists at ('//to_str(first%x)// &
                                      ', '//to_str(first%y)//') (line '//to_str(first%line)// &
                                      '); a line reuses an existing node only where they coincide')
            end if
        end subroutine check_same_node
    end subroutine merge_nodes

    !> Node indices and section indices of elements; checks unknown ids, duplicate element
    !> ids, zero-length and duplicate elements, nodes connected to no element.
    subroutine resolve_elements(deck, elements, section_ids, def_line, beam, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Element candidates in file order.
        type(element_candidate_t), intent(in) :: elements(:)
        !> Deck ids of the sections.
        integer, intent(in) :: section_ids(:)
        !> Deck line defining each node.
        integer, intent(in) :: def_line(:)
        !> Beam configuration (conn, elem_section filled).
        type(beam_config_t), intent(inout) :: beam
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: order(:)
        integer(i8), allocatable :: keys(:)
        logical, allocatable :: connected(:)
        type(deck_entry_t), allocatable :: section_list(:)
        integer :: i, k, ne, a, b
        real(wp) :: size_model, length
        ne = size(elements)
        allocate (beam%conn(2, ne), beam%elem_section(ne), keys(ne))
        size_model = 0.0_wp
        if (size(beam%x) > 0) size_model = hypot(maxval(beam%x) - minval(beam%x), &
                                                 maxval(beam%y) - minval(beam%y))
        do i = 1, ne
            associate (c => elements(i), kw => merge('line   ', 'element', elements(i)%generated))
                do k = 1, 2
                    beam%conn(k, i) = find_node(beam%node_id, c%node(k))
                    if (beam%conn(k, i) == 0) then
                        call make_input_error(error, deck%file, c%line, trim(kw), 'node '// &
                                              to_str(c%node(k))//' is not defined (no node or '// &
                                              'line record creates it)')
                        return
                    end if
                end do
                beam%elem_section(i) = findloc(section_ids, c%section, dim=1)
                if (beam%elem_section(i) == 0) then
                    call make_input_error(error, deck%file, c%line, trim(kw), 'section '// &
                                          to_str(c%section)//' is not defined (no [beam] section '// &
                                          'record with this id)')
                    return
                end if
                a = beam%conn(1, i)
                b = beam%conn(2, i)
                length = hypot(beam%x(b) - beam%x(a), beam%y(b) - beam%y(a))
                if (length <= coincidence*size_model) then
                    call make_input_error(error, deck%file, c%line, trim(kw), &
                                          'zero-length element: '// &
                                          'nodes '//to_str(c%node(1))//' and '//to_str(c%node(2))// &
                                          ' are at the same place')
                    return
                end if
                if (.not. representable_element(beam%sections(beam%elem_section(i)), length)) then
                    section_list = deck%records('beam', 'section')
                    call make_input_error(error, deck%file, c%line, trim(kw), &
                                          'element between nodes '//to_str(c%node(1))//' and '// &
                                          to_str(c%node(2))//' (length '//to_str(length)//' m, section '// &
                                          to_str(c%section)//'): its stiffness or mass (E A / L, 12 E I / L^3, '// &
                                          'rho A L, rho A L^3 / 105) overflows or vanishes in double precision '// &
                                          '(beyond 1.8e308 or below 2.2e-308); check the coordinates and the '// &
                                          '[beam] section on line '//to_str(section_list(beam%elem_section(i))%line))
                    return
                end if
                keys(i) = int(min(a, b), i8)*int(size(beam%x) + 1, i8) + int(max(a, b), i8)
            end associate
        end do
        ! Duplicate element ids (explicit elements) and duplicate node pairs.
        order = sort_index([(merge(0_i8, int(elements(i)%id, i8), elements(i)%generated), &
                             i=1, ne)])
        do i = 2, ne
            associate (c => elements(order(i)), prev => elements(order(i - 1)))
                if (.not. c%generated .and. .not. prev%generated .and. c%id == prev%id) then
                    call make_input_error(error, deck%file, c%line, 'element', &
                                          'duplicate element id '// &
                                          to_str(c%id)//': already defined on line '//to_str(prev%line))
                    return
                end if
            end associate
        end do
        order = sort_index(keys)
        do i = 2, ne
            if (keys(order(i)) == keys(order(i - 1))) then
                associate (c => elements(order(i)), prev => elements(order(i - 1)))
                    call make_input_error(error, deck%file, c%line, &
                                          trim(merge('line   ', 'element', c%generated)), &
                                          'element between nodes '//to_str(c%node(1))//' and '// &
                                          to_str(c%node(2))//' duplicates one defined on line '// &
                                          to_str(prev%line))
                    return
                end associate
            end if
        end do
        allocate (connected(size(beam%x)))
        connected = .false.
        connected(beam%conn(1, :)) = .true.
        connected(beam%conn(2, :)) = .true.
        do i = 1, size(connected)
            if (.not. connected(i)) then
                call make_input_error(error, deck%file, def_line(i), &
                                      beam_keyword_at(deck, def_line(i)), 'node '// &
                                      to_str(beam%node_id(i))//' is connected to no element')
                return
            end if
        end do
    end subroutine resolve_elements

    !> True when the stiffness and mass matrices of an element of this section and length are
    !> finite and their diagonal entries above the smallest normal number: a product such as
    !> E A (area 1e300) or rho A L^3 (coordinates of 1e300) that overflows gives infinite
    !> entries and a run that stops at step 0 on a NaN acceleration; one that underflows, a
    !> singular matrix.
    logical function representable_element(s, length) result(ok)
        type(beam_section_t), intent(in) :: s
        real(wp), intent(in) :: length
        real(wp) :: k(6, 6), m(6, 6), ml(6)
        integer :: j
        k = element_stiffness(s%young*s%area, s%young*s%inertia, length)
        m = element_mass_consistent(s%density*s%area, length)
        ml = element_mass_lumped(s%density*s%area, length)
        ok = all(ieee_is_finite(k)) .and. all(ieee_is_finite(m)) .and. all(ieee_is_finite(ml))
        do j = 1, 3
            ok = ok .and. k(j, j) >= tiny(1.0_wp) .and. m(j, j) >= tiny(1.0_wp) .and. ml(j) >= tiny(1.0_wp)
        end do
    end function representable_element

    !> Fixed DOFs; `fix_line(dof, node)` is the line fixing it (0 = free).
    subroutine build_supports(deck, beam, fix_line, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Beam configuration (fixed filled).
        type(beam_config_t), intent(inout) :: beam
        !> Line of the `fix` record fixing each DOF (0 if free).
        integer, allocatable, intent(out) :: fix_line(:, :)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        type(deck_entry_t) :: e
        type(string_t), allocatable :: dofs(:)
        integer :: i, k, node, dof
        allocate (beam%fixed(3, size(beam%x)), fix_line(3, size(beam%x)))
        beam%fixed = .false.
        fix_line = 0
        allocate (list, source=deck%records('beam', 'fix'))
        do i = 1, size(list)
            e = list(i)
            node = find_node(beam%node_id, e%int('node'))
            if (node == 0) then
                call unknown_node(deck, e, 'fix', error)
                return
            end if
            dofs = e%words_from('dof')
            if (len(repeated_dof(dofs)) > 0) then
                call make_input_error(error, deck%file, e%line, 'fix', 'the DOF '//repeated_dof(dofs)// &
                                      ' is named twice in this record (each of u, w, theta once, or all)')
                return
            end if
            do k = 1, size(dofs)
                if (dofs(k)%s == 'all') then
                    where (fix_line(:, node) == 0) fix_line(:, node) = e%line
                else
                    dof = dof_index(dofs(k)%s)
                    if (fix_line(dof, node) == 0) fix_line(dof, node) = e%line
                end if
            end do
        end do
        beam%fixed = fix_line > 0
    end subroutine build_supports

    !> Nodal loads: known node and function, free DOF.
    subroutine build_loads(deck, function_ids, fix_line, beam, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Deck id of each function.
        integer, intent(in) :: function_ids(:)
        !> Line fixing each DOF (0 if free).
        integer, intent(in) :: fix_line(:, :)
        !> Beam configuration (loads filled).
        type(beam_config_t), intent(inout) :: beam
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        type(deck_entry_t) :: e
        integer :: i
        allocate (list, source=deck%records('beam', 'load'))
        allocate (beam%loads(size(list)))
        do i = 1, size(list)
            e = list(i)
            associate (load => beam%loads(i))
                load%node = find_node(beam%node_id, e%int('node'))
                if (load%node == 0) then
                    call unknown_node(deck, e, 'load', error)
                    return
                end if
                load%dof = dof_index(e%word('dof'))
                if (fix_line(load%dof, load%node) > 0) then
                    call on_fixed_dof(deck, e, 'load', fix_line(load%dof, load%node), error)
                    return
                end if
                load%value = e%real('value')
                load%func = 0
                if (e%has('function')) then
                    load%func = findloc(function_ids, e%int('function'), dim=1)
                    if (load%func == 0) then
                        call make_input_error(error, deck%file, e%line, 'load', 'function '// &
                                              e%word('function')//' is not defined (no [functions] '// &
                                              'function record with this id)')
                        return
                    end if
                end if
            end associate
        end do
    end subroutine build_loads

    !> Distributed loads: each `distributed` record loads every element whose two nodes have
    !> ids from node_a to node_b, with the intensity linear in the projection of the point on
    !> the chord from node_a to node_b (q_a at node_a, q_b at node_b).
    subroutine build_distributed_loads(deck, function_ids, beam, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Deck id of each function.
        integer, intent(in) :: function_ids(:)
        !> Beam configuration (element_loads filled).
        type(beam_config_t), intent(inout) :: beam
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        type(beam_element_load_t), allocatable :: loads(:)
        integer :: i, el, k, a, b, lo, hi, n, direction, func
        real(wp) :: qa, qb, chord(2), t(2)
        logical :: selected(size(beam%conn, 2))
        allocate (list, source=deck%records('beam', 'distributed'))
        allocate (beam%element_loads(0))
        do i = 1, size(list)
            associate (e => list(i))
                a = find_node(beam%node_id, e%int('node_a'))
                b = find_node(beam%node_id, e%int('node_b'))
                if (a == 0 .or. b == 0) then
                    call make_input_error(error, deck%file, e%line, 'distributed', 'node '// &
                                          e%word(merge('node_a', 'node_b', a == 0))//' is not defined (no node '// &
                                          'or line record creates it)')
                    return
                end if
                chord = [beam%x(b) - beam%x(a), beam%y(b) - beam%y(a)]
                if (a == b .or. all(chord == 0.0_wp)) then
                    call make_input_error(error, deck%file, e%line, 'distributed', 'node_a and '// &
                                          'node_b must be two nodes at different places (they give the '// &
                                          'range of elements and the direction of the load variation)')
                    return
                end if
                select case (e%word('direction'))
                case ('x')
                    direction = load_x
                case ('y')
                    direction = load_y
                case ('axial')
                    direction = load_axial
                case default
                    direction = load_transverse
                end select
                qa = e%real('q_a')
                qb = qa
                if (e%has('q_b')) qb = e%real('q_b')
                func = 0
                if (e%has('function')) then
                    func = findloc(function_ids, e%int('function'), dim=1)
                    if (func == 0) then
                        call make_input_error(error, deck%file, e%line, 'distributed', 'function '// &
                                              e%word('function')//' is not defined (no [functions] '// &
                                              'function record with this id)')
                        return
                    end if
                end if
                lo = min(e%int('node_a'), e%int('node_b'))
                hi = max(e%int('node_a'), e%int('node_b'))
                do el = 1, size(beam%conn, 2)
                    selected(el) = all(beam%node_id(beam%conn(:, el)) >= lo .and. &
                                       beam%node_id(beam%conn(:, el)) <= hi)
                end do
                n = count(selected)
                if (n == 0) then
                    call make_input_error(error, deck%file, e%line, 'distributed', 'no element '// &
                                          'has both nodes with ids from '//e%word('node_a')//' to '//e%word('node_b'))
                    return
                end if
                if (allocated(loads)) deallocate (loads)
                allocate (loads(n))
                k = 0
                do el = 1, size(beam%conn, 2)
                    if (.not. selected(el)) cycle
                    ! Position of the element ends on the chord: 0 at node_a, 1 at node_b.
                    t = ((beam%x(beam%conn(:, el)) - beam%x(a))*chord(1) + &
                         (beam%y(beam%conn(:, el)) - beam%y(a))*chord(2))/dot_product(chord, chord)
                    k = k + 1
                    loads(k) = beam_element_load_t(element=el, direction=direction, &
                                                   q=qa + (qb - qa)*t, func=func)
                end do
                beam%element_loads = [beam%element_loads, loads]
            end associate
        end do
    end subroutine build_distributed_loads

    !> Initial displacements and velocities on free DOFs ([initial]).
    subroutine build_initial(deck, beam, fix_line, u0, v0, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Beam configuration.
        type(beam_config_t), intent(in) :: beam
        !> Line fixing each DOF (0 if free).
        integer, intent(in) :: fix_line(:, :)
        !> Initial displacements (3, n_nodes) [m, rad]; zero unless given.
        real(wp), allocatable, intent(out) :: u0(:, :)
        !> Initial velocities (3, n_nodes) [m/s, rad/s]; zero unless given.
        real(wp), allocatable, intent(out) :: v0(:, :)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        allocate (u0(3, size(beam%x)), v0(3, size(beam%x)))
        u0 = 0.0_wp
        v0 = 0.0_wp
        call fill(deck%records('initial', 'displacement'), u0)
        if (allocated(error)) return
        call fill(deck%records('initial', 'velocity'), v0)
        if (allocated(error)) return
        call rigid(deck%records('initial', 'rigid'))

    contains

        !> `rigid` records: node_a node_b vx vy omega xc yc gives the nodes with ids from node_a
        !> to node_b the velocity of a rigid motion, (vx - omega (y - yc), vy + omega (x - xc))
        !> and the rotation rate omega; a fixed DOF must get zero from it.
        subroutine rigid(list)
            type(deck_entry_t), intent(in) :: list(:)
            integer :: i, node, dof, lo, hi, count_nodes
            real(wp) :: v(3)
            do i = 1, size(list)
                associate (e => list(i))
                    lo = min(e%int('node_a'), e%int('node_b'))
                    hi = max(e%int('node_a'), e%int('node_b'))
                    count_nodes = 0
                    do node = 1, size(beam%x)
                        if (beam%node_id(node) < lo .or. beam%node_id(node) > hi) cycle
                        count_nodes = count_nodes + 1
                        v = [e%real('vx') - e%real('omega')*(beam%y(node) - e%real('yc')), &
                             e%real('vy') + e%real('omega')*(beam%x(node) - e%real('xc')), e%real('omega')]
                        do dof = 1, 3
                            if (fix_line(dof, node) == 0) then
                                v0(dof, node) = v(dof)
                            else if (v(dof) /= 0.0_wp) then
                                call make_input_error(error, deck%file, e%line, 'rigid', 'DOF '// &
                                                      trim(dof_word(dof))//' of node '// &
                                                      to_str(beam%node_id(node))//' is fixed (fix on line '// &
                                                      to_str(fix_line(dof, node))//') but the rigid motion '// &
                                                      'gives it '//to_str(v(dof))//'; an initial velocity '// &
                                                      'applies only to a free DOF')
                                return
                            end if
                        end do
                    end do
                    if (count_nodes == 0) then
                        call make_input_error(error, deck%file, e%line, 'rigid', 'no node has an id '// &
                                              'from '//e%word('node_a')//' to '//e%word('node_b'))
                        return
                    end if
                end associate
            end do
        end subroutine rigid

        !> Values of one kind of initial condition from its records.
        subroutine fill(list, values)
            type(deck_entry_t), intent(in) :: list(:)
            real(wp), intent(inout) :: values(:, :)
            integer :: i, node, dof
            integer, allocatable :: given(:, :)
            ! line of the record that gave each DOF its value (0: none yet)
            allocate (given(size(values, 1), size(values, 2)), source=0)
            do i = 1, size(list)
                node = find_node(beam%node_id, list(i)%int('node'))
                if (node == 0) then
                    call unknown_node(deck, list(i), list(i)%keyword, error)
                    return
                end if
                dof = dof_index(list(i)%word('dof'))
                if (fix_line(dof, node) > 0) then
                    call on_fixed_dof(deck, list(i), list(i)%keyword, fix_line(dof, node), error)
                    return
                end if
                if (given(dof, node) > 0) then
                    call make_input_error(error, deck%file, list(i)%line, list(i)%keyword, '[initial] '// &
                                          list(i)%keyword//' of node '//list(i)%word('node')//' '// &
                                          list(i)%word('dof')//' is already given on line '// &
                                          to_str(given(dof, node))//': give each DOF once')
                    return
                end if
                given(dof, node) = list(i)%line
                values(dof, node) = list(i)%real('value')
            end do
        end subroutine fill
    end subroutine build_initial

    ! ---------------------------------------------------------------------------------------
    ! Helpers
    ! ---------------------------------------------------------------------------------------

    !> Error: a record refers to a node id that no node or line defines.
    subroutine unknown_node(deck, e, keyword, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The record.
        type(deck_entry_t), intent(in) :: e
        !> Its keyword.
        character(len=*), intent(in) :: keyword
        !> The error.
        type(error_t), allocatable, intent(out) :: error
        call make_input_error(error, deck%file, e%line, keyword, 'node '//e%word('node')// &
                              ' is not defined (no node or line record creates it)')
    end subroutine unknown_node

    !> Error: a load or initial condition on a fixed DOF.
    subroutine on_fixed_dof(deck, e, keyword, fixed_on, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The record (node, dof, value).
        type(deck_entry_t), intent(in) :: e
        !> Its keyword.
        character(len=*), intent(in) :: keyword
        !> Line of the fix record.
        integer, intent(in) :: fixed_on
        !> The error.
        type(error_t), allocatable, intent(out) :: error
        call make_input_error(error, deck%file, e%line, keyword, 'DOF '//e%word('dof')//' of node '// &
                              e%word('node')//' is fixed (fix on line '//to_str(fixed_on)// &
                              '); a '//keyword//' applies only to a free DOF')
    end subroutine on_fixed_dof

    !> DOF word (u, w, theta) of a DOF index.
    pure function dof_word(dof) result(word)
        !> dof_u, dof_w or dof_theta.
        integer, intent(in) :: dof
        character(len=5) :: word
        character(len=5), parameter :: words(3) = ['u    ', 'w    ', 'theta']
        word = words(dof)
    end function dof_word

    !> DOF index of a DOF word: u, w, theta or their [particles] names x, y, rot.
    !> The first DOF word of a `fix` record that names a DOF already named in the record
    !> ('all' names the three), or '' when each is named once: `fix = 1 u u u` (meant
    !> u w theta) would otherwise fix one DOF without a word.
    pure function repeated_dof(words) result(word)
        !> The DOF words of the record ('u'/'x', 'w'/'y', 'theta'/'rot', 'all').
        type(string_t), intent(in) :: words(:)
        character(len=:), allocatable :: word
        logical :: named(3)
        integer :: k
        named = .false.
        word = ''
        do k = 1, size(words)
            if (words(k)%s == 'all') then
                if (any(named)) word = 'all'
                if (any(named)) return
                named = .true.
            else
                if (named(dof_index(words(k)%s))) then
                    word = words(k)%s
                    return
                end if
                named(dof_index(words(k)%s)) = .true.
            end if
        end do
    end function repeated_dof

    pure integer function dof_index(word)
        !> 'u' or 'x', 'w' or 'y', 'theta' or 'rot'.
        character(len=*), intent(in) :: word
        select case (word)
        case ('u', 'x')
            dof_index = dof_u
        case ('w', 'y')
            dof_index = dof_w
        case default
            dof_index = dof_theta
        end select
    end function dof_index

    !> Node index of a deck node id (binary search in the increasing ids; 0 if absent).
    pure integer function find_node(node_id, id) result(k)
        !> Deck ids of the nodes, increasing.
        integer, intent(in) :: node_id(:)
        !> Id wanted.
        integer, intent(in) :: id
        integer :: lo, hi
        lo = 1
        hi = size(node_id)
        do while (lo <= hi)
            k = (lo + hi)/2
            if (node_id(k) == id) return
            if (node_id(k) < id) then
                lo = k + 1
            else
                hi = k - 1
            end if
        end do
        k = 0
    end function find_node
end module driver_config_beam
