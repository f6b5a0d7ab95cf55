!> A 2D linear-elastic continuum on a mesh: dof numbering, assembly and boundary conditions.
!>
!> Dofs: node a has dofs 2a - 1 (x) and 2a (y). Global matrices are assembled over all dofs as
!> triplets (`fem_triplets_t`, both triangles, duplicates summed). Prescribed displacements are
!> imposed by elimination: the free dofs are numbered 1..n_equations (`equation`), and
!> `reduce` returns K_ff and f_f - K_fp u_p, which stay symmetric positive definite when the
!> prescribed dofs remove the rigid motions; `expand` puts u_f and u_p back together.
!>
!> A prescribed dof is constant (its value) or its value times one of the model's time
!> functions, u_p(t) = value f(t) (`prescribed_function`). `reduce` moves only the constant
!> ones to the right-hand side; the timed ones enter the loads of the free dofs at each time
!> (fem_continuum_dynamics), and `prescribed_at` gives u_p(t), its rate and its acceleration.
module fem_continuum_model
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp
    use core_constants, only: singular_ratio
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use core_timefunc, only: time_function_slot_t
    use fem_elastic2d, only: elastic2d_t
    use fem_element_registry, only: element_slot_t, element_family, kind_node_count
    use fem_edge_load, only: edge_traction_linear, edge_traction_normal_tangential, &
                             edge_traction_function, traction_field_t, parabolic_traction_t
    use fem_mesh2d, only: mesh2d_t
    use fem_triplets, only: fem_triplets_t
    use fem_mass_scheme, only: mass_scheme_t
    implicit none
    private
    public :: continuum_model_t

    !> The continuum model.
    type :: continuum_model_t
        !> The mesh.
        type(mesh2d_t) :: mesh
        !> Materials.
        type(elastic2d_t), allocatable :: materials(:)
        !> Material index of each element (0 until assigned).
        integer, allocatable :: element_material(:)
        !> One element of every kind, indexed by kind id (fem_element_registry).
        type(element_slot_t), allocatable :: family(:)
        !> Prescribed flag of each dof.
        logical, allocatable :: prescribed(:)
        !> Prescribed value of each dof (m; 0 where free); for a timed dof, the amplitude.
        real(wp), allocatable :: prescribed_value(:)
        !> Time function of each prescribed dof (index into `functions`; 0: constant value).
        integer, allocatable :: prescribed_function(:)
        !> External nodal forces (N), size 2 * number of nodes (constant in time).
        real(wp), allocatable :: load(:)
        !> Time functions multiplying the columns of `timed_load` (none: every load constant).
        type(time_function_slot_t), allocatable :: functions(:)
        !> Nodal forces (N) times a time function: column k (size 2 * number of nodes) is
        !> multiplied by functions(k)(t); size (dof_count, size(functions)).
        real(wp), allocatable :: timed_load(:, :)
    contains
        !> Take a mesh, check its elements, and start with no material, load or constraint.
        procedure :: init => model_init
        !> Number of dofs (2 per node).
        procedure :: dof_count => model_dof_count
        !> Assign a material to the elements of a named element set.
        procedure :: set_material => model_set_material
        !> Prescribe one dof (component 1 = x, 2 = y) of a node.
        procedure :: prescribe => model_prescribe
        !> Prescribe one component on every node of a named node set.
        procedure :: prescribe_set => model_prescribe_set
        !> Add a nodal force.
        procedure :: add_nodal_load => model_add_nodal_load
        !> Add the weight rho t g of every element.
        procedure :: add_body_force => model_add_body_force
        !> Add a uniform traction (tx, ty) on a named edge set.
        procedure :: add_traction => model_add_traction
        !> Add a uniform normal/tangential traction on a named edge set.
        procedure :: add_traction_nt => model_add_traction_nt
        !> Add a traction field t(x) on a named edge set.
        procedure :: add_traction_field => model_add_traction_field
        !> Add a parabolic traction across a named edge set whose resultant is that of a
        !> uniform (tx, ty).
        procedure :: add_traction_parabolic => model_add_traction_parabolic
        !> Check that every element has a material.
        procedure :: check => model_check
        !> First element whose matrices overflow or vanish in double precision (0: none).
        procedure :: unrepresentable_element => model_unrepresentable_element
        !> Global stiffness (all dofs) as triplets.
        procedure :: assemble_stiffness => model_assemble_stiffness
        !> Global mass (all dofs) under a mass scheme (consistent or row-sum lumped), as triplets.
        procedure :: assemble_mass => model_assemble_mass
        !> Equation number of each dof (0 for prescribed dofs) and their count.
        procedure :: equations => model_equations
        !> Eliminate the prescribed dofs from K u = f.
        procedure :: reduce => model_reduce
        !> Full displacement vector from the free-dof solution and the prescribed values.
        procedure :: expand => model_expand
        !> u_p(t), its rate or its acceleration over all dofs (0 on the free dofs).
        procedure :: prescribed_at => model_prescribed_at
        !> Whether some prescribed dof follows a time function.
        procedure :: has_timed_prescribed => model_has_timed_prescribed
        !> Stress (xx, yy, xy) at every element centre.
        procedure :: centre_stresses => model_centre_stresses
        !> Out-of-plane stress sigma_zz and von Mises stress of every element from its in-plane
        !> stress (xx, yy, xy), by the element's material.
        procedure :: stress_measures => model_stress_measures
        !> Whether the prescribed dofs stop the three rigid motions of the plane of every body.
        procedure :: stops_rigid_motions => model_stops_rigid_motions
        !> First body of the mesh whose rigid motions the prescribed dofs do not stop (0: none).
        procedure :: unheld_body => model_unheld_body
    end type continuum_model_t

    !> Largest aspect ratio of an element (aspect_ratio). The stiffness of an element scales
    !> with its shape's condition, about the square of the ratio: at 1e6 it is 1e12 against
    !> the round-off of 1e-16 of the sums that assemble it. Far beyond any usable element
    !> (accuracy is lost long before; Gmsh's meshes of a body stay below 10).
    real(wp), parameter :: max_aspect = 1.0e6_wp

contains

    !> Take a mesh and check that no element is inverted, degenerate or needle-thin.
    subroutine model_init(self, mesh, error)
        !> The model.
        class(continuum_model_t), intent(out) :: self
        !> The mesh (copied).
        type(mesh2d_t), intent(in) :: mesh
        !> Set when the mesh is empty, an element has det J <= 0 somewhere, or an edge of an
        !> edge set is not a side of any element.
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        real(wp), allocatable :: xe(:, :)
        call element_family(self%family)
        self%mesh = mesh
        if (mesh%element_count() == 0) then
            call make_error(error, 'continuum model: the mesh has no element')
            return
        end if
        do e = 1, mesh%element_count()
            associate (el => self%family(mesh%kind(e))%element)
                xe = mesh%element_coordinates(e)
                if (.not. el%min_jacobian(xe) > 0.0_wp) then
                    call make_error(error, 'continuum model: '//mesh%element_label(e)//' is inverted, '// &
                                    'degenerate or not convex (det J <= 0)')
                    return
                end if
                if (aspect_ratio(xe) > max_aspect) then
                    call make_error(error, 'continuum model: '//mesh%element_label(e)//' has an aspect ratio of '// &
                                    to_str(aspect_ratio(xe))//' (longest side over smallest height), above '// &
                                    to_str(max_aspect)//': its stiffness is lost in the rounding of double '// &
                                    'precision; mesh the body with elements of reasonable shape')
                    return
                end if
            end associate
        end do
        ! Edge loads need the body on the left of each edge and the element carrying it.
        call self%mesh%orient_edges(error)
        if (allocated(error)) return
        allocate (self%materials(0))
        allocate (self%element_material(mesh%element_count()), source=0)
        allocate (self%prescribed(self%dof_count()), source=.false.)
        allocate (self%prescribed_function(self%dof_count()), source=0)
        allocate (self%prescribed_value(self%dof_count()), self%load(self%dof_count()), source=0.0_wp)
        allocate (self%functions(0), self%timed_load(self%dof_count(), 0))
    end subroutine model_init

    !> Longest side of an element over its smallest height: the heights of the triangles of
    !> each side with the next corner (a T3's own three heights; for a Q4, the four corner
    !> triangles). 1 for a square, 2/sqrt(3) for an equilateral triangle.
    pure real(wp) function aspect_ratio(xe) result(ratio)
        !> Node coordinates (2, 3 or 4), counter-clockwise.
        real(wp), intent(in) :: xe(:, :)
        real(wp) :: longest, height, side, twice_area
        integer :: m, i, j, k
        m = size(xe, 2)
        longest = 0.0_wp
        do i = 1, m
            longest = max(longest, hypot(xe(1, mod(i, m) + 1) - xe(1, i), xe(2, mod(i, m) + 1) - xe(2, i)))
        end do
        height = huge(1.0_wp)
        do i = 1, m
            j = mod(i, m) + 1
            k = mod(i + 1, m) + 1
            side = hypot(xe(1, j) - xe(1, i), xe(2, j) - xe(2, i))
            twice_area = abs((xe(1, j) - xe(1, i))*(xe(2, k) - xe(2, i)) - (xe(2, j) - xe(2, i))*(xe(1, k) - xe(1, i)))
            if (side > 0.0_wp) height = min(height, twice_area/side)
        end do
        ratio = huge(1.0_wp)
        if (height > 0.0_wp) ratio = longest/height
    end function aspect_ratio

    !> Number of dofs.
    pure integer function model_dof_count(self)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        model_dof_count = 2*self%mesh%node_count()
    end function model_dof_count

    !> Global dofs of element e.
    pure function element_dofs(self, e) result(dofs)
        class(continuum_model_t), intent(in) :: self
        integer, intent(in) :: e
        integer, allocatable :: dofs(:)
        integer :: n
        n = kind_node_count(self%mesh%kind(e))
        allocate (dofs(2*n))
        dofs(1::2) = 2*self%mesh%connectivity(1:n, e) - 1
        dofs(2::2) = 2*self%mesh%connectivity(1:n, e)
    end function element_dofs

    !> Assign a material to the elements of a named set (later assignments override).
    subroutine model_set_material(self, set_name, material, error)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Element set name ('all' for a generated mesh).
        character(len=*), intent(in) :: set_name
        !> The material.
        type(elastic2d_t), intent(in) :: material
        !> Set when the set is unknown.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: ids(:)
        call self%mesh%element_set(set_name, ids, error)
        if (allocated(error)) return
        self%materials = [self%materials, material]
        self%element_material(ids) = size(self%materials)
    end subroutine model_set_material

    !> Prescribe the displacement of one dof.
    pure subroutine model_prescribe(self, node, component, value, function)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Node index.
        integer, intent(in) :: node
        !> 1 = x, 2 = y.
        integer, intent(in) :: component
        !> Displacement (m).
        real(wp), intent(in) :: value
        !> Index of the time function multiplying the value (absent or 0: constant).
        integer, intent(in), optional :: function
        self%prescribed(2*node - 2 + component) = .true.
        self%prescribed_value(2*node - 2 + component) = value
        self%prescribed_function(2*node - 2 + component) = 0
        if (present(function)) self%prescribed_function(2*node - 2 + component) = function
    end subroutine model_prescribe

    !> Prescribe one displacement component on every node of a named node set.
    subroutine model_prescribe_set(self, set_name, component, value, error, function)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Node set name.
        character(len=*), intent(in) :: set_name
        !> 1 = x, 2 = y.
        integer, intent(in) :: component
        !> Displacement (m).
        real(wp), intent(in) :: value
        !> Set when the set is unknown, the component is not 1 or 2, or the function index is
        !> not one of `functions`.
        type(error_t), allocatable, intent(out) :: error
        !> Index of the time function multiplying the value (absent or 0: constant).
        integer, intent(in), optional :: function
        integer, allocatable :: ids(:)
        integer :: k, f
        if (component /= 1 .and. component /= 2) then
            call make_error(error, 'continuum model: displacement component must be 1 (x) or 2 (y)')
            return
        end if
        f = 0
        if (present(function)) f = function
        if (f < 0 .or. f > size(self%functions)) then
            call make_error(error, 'continuum model: the prescribed displacement names no time function of the model')
            return
        end if
        call self%mesh%node_set(set_name, ids, error)
        if (allocated(error)) return
        do k = 1, size(ids)
            call self%prescribe(ids(k), component, value, f)
        end do
    end subroutine model_prescribe_set

    !> Add a nodal force.
    pure subroutine model_add_nodal_load(self, node, component, force)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Node index.
        integer, intent(in) :: node
        !> 1 = x, 2 = y.
        integer, intent(in) :: component
        !> Force (N).
        real(wp), intent(in) :: force
        self%load(2*node - 2 + component) = self%load(2*node - 2 + component) + force
    end subroutine model_add_nodal_load

    !> Add the equivalent nodal forces of the weight of every element.
    subroutine model_add_body_force(self, g, error)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Acceleration of gravity (m/s^2).
        real(wp), intent(in) :: g(2)
        !> Set when an element has no material.
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        integer, allocatable :: dofs(:)
        call self%check(error)
        if (allocated(error)) return
        do e = 1, self%mesh%element_count()
            dofs = element_dofs(self, e)
            associate (el => self%family(self%mesh%kind(e))%element, mat => self%materials(self%element_material(e)))
                self%load(dofs) = self%load(dofs) + el%body_force(self%mesh%element_coordinates(e), mat, g)
            end associate
        end do
    end subroutine model_add_body_force

    !> Thickness of the material of the element carrying an edge, for edge loads.
    subroutine edge_thickness(self, element, thickness, error)
        class(continuum_model_t), intent(in) :: self
        integer, intent(in) :: element
        real(wp), intent(out) :: thickness
        type(error_t), allocatable, intent(out) :: error
        thickness = 0.0_wp
        if (self%element_material(element) == 0) then
            call make_error(error, 'continuum model: a loaded edge is a side of '//self%mesh%element_label(element)// &
                            ', which has no material')
            return
        end if
        thickness = self%materials(self%element_material(element))%thickness
    end subroutine edge_thickness

    !> Add a uniform traction (tx, ty) (Pa) on the edges of a named edge set.
    subroutine model_add_traction(self, set_name, traction, error)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Edge set name.
        character(len=*), intent(in) :: set_name
        !> Traction (tx, ty) (Pa).
        real(wp), intent(in) :: traction(2)
        !> Set when the set is unknown or an edge has no element with a material.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: edges(:, :), owner(:)
        integer :: k
        real(wp) :: t, xa(2), xb(2)
        call self%mesh%edge_set(set_name, edges, error, owner)
        if (allocated(error)) return
        do k = 1, size(edges, 2)
            call edge_thickness(self, owner(k), t, error)
            if (allocated(error)) return
            xa = self%mesh%x(:, edges(1, k))
            xb = self%mesh%x(:, edges(2, k))
            call scatter_edge(self, edges(:, k), edge_traction_linear(xa, xb, traction, traction, t))
        end do
    end subroutine model_add_traction

    !> Add a uniform traction given by its normal (> 0 pulls) and tangential components (Pa).
    subroutine model_add_traction_nt(self, set_name, normal, tangential, error)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Edge set name.
        character(len=*), intent(in) :: set_name
        !> Normal traction (Pa); a pressure p is -p.
        real(wp), intent(in) :: normal
        !> Tangential traction (Pa), positive counter-clockwise along the boundary.
        real(wp), intent(in) :: tangential
        !> Set when the set is unknown or an edge has no element with a material.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: edges(:, :), owner(:)
        integer :: k
        real(wp) :: t, xa(2), xb(2)
        call self%mesh%edge_set(set_name, edges, error, owner)
        if (allocated(error)) return
        do k = 1, size(edges, 2)
            call edge_thickness(self, owner(k), t, error)
            if (allocated(error)) return
            xa = self%mesh%x(:, edges(1, k))
            xb = self%mesh%x(:, edges(2, k))
            call scatter_edge(self, edges(:, k), edge_traction_normal_tangential(xa, xb, normal, tangential, t))
        end do
    end subroutine model_add_traction_nt

    !> Add a traction field t(x) on the edges of a named edge set (3-point Gauss per edge).
    subroutine model_add_traction_field(self, set_name, traction, error)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Edge set name.
        character(len=*), intent(in) :: set_name
        !> Traction field.
        class(traction_field_t), intent(in) :: traction
        !> Set when the set is unknown or an edge has no element with a material.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: edges(:, :), owner(:)
        integer :: k
        real(wp) :: t, xa(2), xb(2)
        call self%mesh%edge_set(set_name, edges, error, owner)
        if (allocated(error)) return
        do k = 1, size(edges, 2)
            call edge_thickness(self, owner(k), t, error)
            if (allocated(error)) return
            xa = self%mesh%x(:, edges(1, k))
            xb = self%mesh%x(:, edges(2, k))
            call scatter_edge(self, edges(:, k), edge_traction_function(xa, xb, traction, t))
        end do
    end subroutine model_add_traction_field

    !> Add the parabolic traction 1.5 t (1 - s^2) across a named edge set, s = -1..1 along the
    !> longer extent of the set (the end shear of a beam): the resultant of the uniform t.
    subroutine model_add_traction_parabolic(self, set_name, t, error)
        !> The model.
        class(continuum_model_t), intent(inout) :: self
        !> Edge set name.
        character(len=*), intent(in) :: set_name
        !> Mean traction (tx, ty) (Pa).
        real(wp), intent(in) :: t(2)
        !> Set when the set is unknown or an edge has no element with a material.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: edges(:, :)
        real(wp) :: lo(2), hi(2)
        integer :: axis
        call self%mesh%edge_set(set_name, edges, error)
        if (allocated(error)) return
        lo = minval(self%mesh%x(:, reshape(edges, [size(edges)])), dim=2)
        hi = maxval(self%mesh%x(:, reshape(edges, [size(edges)])), dim=2)
        axis = merge(1, 2, hi(1) - lo(1) >= hi(2) - lo(2))
        call self%add_traction_field(set_name, parabolic_traction_t(mean=t, axis=axis, lo=lo(axis), &
                                                                    hi=hi(axis)), error)
    end subroutine model_add_traction_parabolic

    !> Add edge forces (f_ax, f_ay, f_bx, f_by) to the load vector.
    pure subroutine scatter_edge(self, nodes, f)
        class(continuum_model_t), intent(inout) :: self
        integer, intent(in) :: nodes(2)
        real(wp), intent(in) :: f(4)
        self%load(2*nodes(1) - 1:2*nodes(1)) = self%load(2*nodes(1) - 1:2*nodes(1)) + f(1:2)
        self%load(2*nodes(2) - 1:2*nodes(2)) = self%load(2*nodes(2) - 1:2*nodes(2)) + f(3:4)
    end subroutine scatter_edge

    !> Check that every element has a material.
    subroutine model_check(self, error)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Set when an element has no material.
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        do e = 1, size(self%element_material)
            if (self%element_material(e) == 0) then
                call make_error(error, 'continuum model: '//self%mesh%element_label(e)// &
                                ' has no material (assign one to an element set containing it)')
                return
            end if
        end do
    end subroutine model_check

    !> First element whose stiffness or mass matrix cannot be represented (0: none): an entry
    !> that overflows (a thickness or modulus of 1e300 gives E t beyond 1.8e308) or a diagonal
    !> entry below the smallest normal number (a singular matrix); the mass only for a density
    !> > 0 (a static analysis may have none). Every element must have a material (check).
    integer function model_unrepresentable_element(self) result(bad)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        real(wp), allocatable :: k(:, :), m(:, :), ml(:)
        integer :: e, a
        logical :: ok
        bad = 0
        do e = 1, self%mesh%element_count()
            associate (el => self%family(self%mesh%kind(e))%element, &
                       xe => self%mesh%element_coordinates(e), mat => self%materials(self%element_material(e)))
                k = el%stiffness(xe, mat)
                m = el%mass_consistent(xe, mat)
                ml = el%mass_lumped(xe, mat)
                ok = all(ieee_is_finite(k)) .and. all(ieee_is_finite(m)) .and. all(ieee_is_finite(ml))
                do a = 1, size(ml)
                    ok = ok .and. k(a, a) >= tiny(1.0_wp)
                    if (mat%density > 0.0_wp) ok = ok .and. m(a, a) >= tiny(1.0_wp) .and. ml(a) >= tiny(1.0_wp)
                end do
            end associate
            if (.not. ok) then
                bad = e
                return
            end if
        end do
    end function model_unrepresentable_element

    !> Global stiffness over all dofs.
    subroutine model_assemble_stiffness(self, k, error)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Stiffness (dof_count x dof_count) as triplets.
        type(fem_triplets_t), intent(out) :: k
        !> Set when an element has no material.
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        call self%check(error)
        if (allocated(error)) return
        call k%init(self%dof_count(), 64*self%mesh%element_count())
        do e = 1, self%mesh%element_count()
            associate (el => self%family(self%mesh%kind(e))%element, mat => self%materials(self%element_material(e)))
                call k%add_block(element_dofs(self, e), el%stiffness(self%mesh%element_coordinates(e), mat))
            end associate
        end do
    end subroutine model_assemble_stiffness

    !> Global mass over all dofs under a mass scheme: consistent, or row-sum lumped (diagonal
    !> triplets only).
    subroutine model_assemble_mass(self, scheme, m, error)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> How the element masses enter (fem_mass_scheme).
        class(mass_scheme_t), intent(in) :: scheme
        !> Mass (dof_count x dof_count) as triplets.
        type(fem_triplets_t), intent(out) :: m
        !> Set when an element has no material.
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        call self%check(error)
        if (allocated(error)) return
        call m%init(self%dof_count(), merge(8, 64, scheme%is_diagonal())*self%mesh%element_count())
        do e = 1, self%mesh%element_count()
            associate (el => self%family(self%mesh%kind(e))%element, &
                       xe => self%mesh%element_coordinates(e), mat => self%materials(self%element_material(e)))
                call scheme%add_element(m, element_dofs(self, e), el%mass_consistent(xe, mat), el%mass_lumped(xe, mat))
            end associate
        end do
    end subroutine model_assemble_mass

    !> Equation number of each dof: free dofs numbered 1..n in dof order, prescribed dofs 0.
    pure subroutine model_equations(self, equation, n)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Equation number of each dof (dof_count).
        integer, allocatable, intent(out) :: equation(:)
        !> Number of equations (free dofs).
        integer, intent(out) :: n
        integer :: i
        allocate (equation(self%dof_count()), source=0)
        n = 0
        do i = 1, self%dof_count()
            if (self%prescribed(i)) cycle
            n = n + 1
            equation(i) = n
        end do
    end subroutine model_equations

    !> Eliminate the prescribed dofs: kr = K_ff, fr = f_f - K_fp u_p over the constant
    !> prescribed dofs (the timed ones are left to the caller, at each time).
    pure subroutine model_reduce(self, k, f, kr, fr)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Stiffness over all dofs.
        type(fem_triplets_t), intent(in) :: k
        !> Forces over all dofs (dof_count).
        real(wp), intent(in) :: f(:)
        !> Stiffness over the free dofs (equation numbers).
        type(fem_triplets_t), intent(out) :: kr
        !> Right-hand side over the free dofs.
        real(wp), allocatable, intent(out) :: fr(:)
        integer, allocatable :: eq(:)
        integer :: n, p, i, j
        call self%equations(eq, n)
        call kr%init(n, k%nnz)
        allocate (fr(n))
        do i = 1, size(eq)
            if (eq(i) > 0) fr(eq(i)) = f(i)
        end do
        do p = 1, k%nnz
            i = eq(k%i(p))
            j = eq(k%j(p))
            if (i == 0) cycle
            if (j > 0) then
                call kr%add(i, j, k%v(p))
            else if (self%prescribed_function(k%j(p)) == 0) then
                fr(i) = fr(i) - k%v(p)*self%prescribed_value(k%j(p))
            end if
        end do
    end subroutine model_reduce

    !> Full displacement vector: free dofs from the solution, prescribed dofs from their values
    !> at time t (default 0), or their rates (derivative 1) or accelerations (2).
    pure function model_expand(self, ur, t, derivative) result(u)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Solution over the free dofs.
        real(wp), intent(in) :: ur(:)
        !> Time [s] (default 0).
        real(wp), intent(in), optional :: t
        !> 0: displacements (default), 1: velocities, 2: accelerations of the prescribed dofs.
        integer, intent(in), optional :: derivative
        !> Displacements over all dofs.
        real(wp), allocatable :: u(:)
        integer, allocatable :: eq(:)
        integer :: n, i, order
        real(wp) :: time
        time = 0.0_wp
        if (present(t)) time = t
        order = 0
        if (present(derivative)) order = derivative
        call self%equations(eq, n)
        u = self%prescribed_at(time, order)
        do i = 1, size(eq)
            if (eq(i) > 0) u(i) = ur(eq(i))
        end do
    end function model_expand

    !> Prescribed displacements at time t over all dofs (0 on the free dofs): the value, or
    !> value f(t) for a timed dof; derivative 1 and 2 give the rates value f'(t) and
    !> accelerations value f''(t) (0 for the constant dofs).
    pure function model_prescribed_at(self, t, derivative) result(up)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> 0: displacement, 1: rate, 2: acceleration.
        integer, intent(in) :: derivative
        !> u_p(t) or its derivative over all dofs.
        real(wp), allocatable :: up(:)
        real(wp), allocatable :: f(:)
        integer :: i, k
        allocate (f(0:size(self%functions)))
        f(0) = merge(1.0_wp, 0.0_wp, derivative == 0)
        do k = 1, size(self%functions)
            select case (derivative)
            case (0)
                f(k) = self%functions(k)%fn%value(t)
            case (1)
                f(k) = self%functions(k)%fn%rate(t)
            case default
                f(k) = self%functions(k)%fn%acceleration(t)
            end select
        end do
        allocate (up(self%dof_count()), source=0.0_wp)
        do i = 1, size(up)
            if (self%prescribed(i)) up(i) = self%prescribed_value(i)*f(self%prescribed_function(i))
        end do
    end function model_prescribed_at

    !> Whether some prescribed dof follows a time function.
    pure logical function model_has_timed_prescribed(self) result(timed)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        timed = any(self%prescribed .and. self%prescribed_function > 0)
    end function model_has_timed_prescribed

    !> Stress (xx, yy, xy) at the centre of every element for the displacements u.
    subroutine model_centre_stresses(self, u, stress, error)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Displacements over all dofs.
        real(wp), intent(in) :: u(:)
        !> Stresses (3, number of elements) (Pa).
        real(wp), allocatable, intent(out) :: stress(:, :)
        !> Set when an element has no material.
        type(error_t), allocatable, intent(out) :: error
        integer :: e
        call self%check(error)
        if (allocated(error)) return
        allocate (stress(3, self%mesh%element_count()))
        do e = 1, self%mesh%element_count()
            associate (el => self%family(self%mesh%kind(e))%element, mat => self%materials(self%element_material(e)))
                stress(:, e) = el%stress_centre(self%mesh%element_coordinates(e), mat, u(element_dofs(self, e)))
            end associate
        end do
    end subroutine model_centre_stresses

    !> sigma_zz and von Mises stress of every element (fem_elastic2d: sigma_zz = nu (sigma_xx +
    !> sigma_yy) in plane strain, 0 in plane stress) from its stress (xx, yy, xy), such as the
    !> centre stresses of `centre_stresses`.
    pure subroutine model_stress_measures(self, stress, sigma_zz, von_mises)
        !> The model (its materials assigned: `check`).
        class(continuum_model_t), intent(in) :: self
        !> Stresses (3, number of elements) [Pa].
        real(wp), intent(in) :: stress(:, :)
        !> sigma_zz of each element [Pa].
        real(wp), allocatable, intent(out) :: sigma_zz(:)
        !> Von Mises stress of each element [Pa].
        real(wp), allocatable, intent(out) :: von_mises(:)
        integer :: e
        allocate (sigma_zz(size(stress, 2)), von_mises(size(stress, 2)))
        do e = 1, size(stress, 2)
            associate (mat => self%materials(self%element_material(e)))
                sigma_zz(e) = mat%sigma_zz(stress(:, e))
                von_mises(e) = mat%von_mises(stress(:, e))
            end associate
        end do
    end subroutine model_stress_measures

    !> Whether the prescribed dofs stop the rigid motions of every body (unheld_body is 0).
    pure logical function model_stops_rigid_motions(self) result(stops)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        stops = self%unheld_body() == 0
    end function model_stops_rigid_motions

    !> First body (connected part of the mesh, `mesh2d_t%bodies`) whose rigid motions (two
    !> translations and the rotation) the prescribed dofs do not stop (0: every body is held).
    !> Each body is its own rigid system: supports on one hold nothing of another, so the
    !> test is per body: the rows (1, 0, -y) of its prescribed x dofs and (0, 1, x) of its
    !> prescribed y dofs (coordinates from the body's centroid, scaled by its size) have rank 3,
    !> judged by det(G^T G) > 1e-12 (trace/3)^3. A part joined to the rest by a single node (a
    !> hinge) is in the same body and passes: its free rotation shows in the factorisation.
    pure integer function model_unheld_body(self, body) result(unheld)
        !> The model.
        class(continuum_model_t), intent(in) :: self
        !> Body of each node (as from `mesh%bodies`; computed when absent).
        integer, intent(in), optional :: body(:)
        integer, allocatable :: of(:)
        real(wp) :: g(3, 3), r(3), c(2), extent, det
        integer :: a, k, b, n_bodies
        logical, allocatable :: in(:)
        if (present(body)) then
            of = body
            n_bodies = 0
            if (size(of) > 0) n_bodies = maxval(of)
        else
            call self%mesh%bodies(of, n_bodies)
        end if
        unheld = 0
        do b = 1, n_bodies
            in = of == b
            c = [sum(self%mesh%x(1, :), mask=in), sum(self%mesh%x(2, :), mask=in)]/real(count(in), wp)
            extent = max(maxval(abs(self%mesh%x(1, :) - c(1)), mask=in), &
                         maxval(abs(self%mesh%x(2, :) - c(2)), mask=in), tiny(1.0_wp))
            g = 0.0_wp
            do a = 1, self%mesh%node_count()
                if (.not. in(a)) cycle
                do k = 1, 2
                    if (.not. self%prescribed(2*a - 2 + k)) cycle
                    if (k == 1) r = [1.0_wp, 0.0_wp, -(self%mesh%x(2, a) - c(2))/extent]
                    if (k == 2) r = [0.0_wp, 1.0_wp, (self%mesh%x(1, a) - c(1))/extent]
                    g = g + spread(r, 2, 3)*spread(r, 1, 3)
                end do
            end do
            det = g(1, 1)*(g(2, 2)*g(3, 3) - g(2, 3)*g(3, 2)) - g(1, 2)*(g(2, 1)*g(3, 3) - g(2, 3)*g(3, 1)) &
                  + g(1, 3)*(g(2, 1)*g(3, 2) - g(2, 2)*g(3, 1))
            if (.not. (det > singular_ratio*((g(1, 1) + g(2, 2) + g(3, 3))/3)**3 .and. det > 0)) then
                unheld = b
                return
            end if
        end do

    end function model_unheld_body
end module fem_continuum_model
