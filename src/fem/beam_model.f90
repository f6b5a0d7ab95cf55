!> Assembled planar frame model: equation numbering, band stiffness and mass, Rayleigh
!> damping, loads, and the vector operations the solvers and time integrators need.
!>
!> Free DOFs are numbered node by node (u, w, theta), which keeps the bandwidth at most
!> 3*(largest node-number difference in an element) + 2. All vectors of size `n_free`
!> are in that numbering; `expand` and `restrict` convert to and from (3, n_nodes) arrays.
!>
!> Arlequin weighting (doc/theory.md, section 6.2): given a weight alpha(s) (s = `abscissa`, the
!> distance from node 1 along the elements), mass and stiffness are integrated as
!> int alpha(s) (...) ds by Gauss quadrature (6 points on each piece of an element between
!> the weight's breakpoints: exact for a piecewise cubic alpha times the degree-6 Hermite
!> mass products), and so is the self-weight (int alpha rho A g N ds: gravity acts through the
!> weighted mass). The loads of the deck (nodal and distributed) are not weighted: they are
!> given to the beam only, the disks carry no share of them, so the beam applies them in full.
module fem_beam_model
    use core_kinds, only: wp
    use core_constants, only: relative_roundoff, singular_ratio
    use core_error, only: error_t, make_error, make_internal_error
    use core_linalg, only: band_spd_t, largest_generalized_eigenvalue, dense_generalized_eigen
    use core_sort, only: sort_in_place
    use core_timefunc, only: time_function_slot_t
    use core_weight, only: weight_function_t
    use fem_dynamic_operator, only: dynamic_operator_t, spd_factor_t
    use fem_mass_scheme, only: consistent_mass_t
    use fem_beam_config, only: beam_config_t, beam_load_t, beam_section_t, &
                               load_x, load_y, load_axial, load_transverse
    use fem_beam_element, only: element_stiffness, element_mass_consistent, &
                                element_mass_lumped, to_global, hermite_shape, rotation_matrix
    implicit none
    private
    public :: beam_model_t, build_beam_model

    !> Names of the DOFs of a node, for messages.
    character(len=5), parameter :: dof_names(3) = ['u    ', 'w    ', 'theta']

    !> 6-point Gauss-Legendre rule on [0, 1] (exact to degree 11): abscissas and weights.
    real(wp), parameter :: gauss_t(6) = 0.5_wp + 0.5_wp*[ &
                           -0.9324695142031520278123016_wp, -0.6612093864662645136613996_wp, &
                           -0.2386191860831969086305017_wp, 0.2386191860831969086305017_wp, &
                           0.6612093864662645136613996_wp, 0.9324695142031520278123016_wp]
    !> See `gauss_t`.
    real(wp), parameter :: gauss_w(6) = 0.5_wp*[ &
                           0.1713244923791703450402961_wp, 0.3607615730481386075698025_wp, &
                           0.4679139345726910473898703_wp, 0.4679139345726910473898703_wp, &
                           0.3607615730481386075698025_wp, 0.1713244923791703450402961_wp]

    !> A planar Euler-Bernoulli frame ready for static, modal and transient analysis. From
    !> `dynamic_operator_t`: n_free, mass_scheme (lumped: HRZ, diagonal, `m%kd` = 0), rayleigh_a0/a1.
    type, extends(dynamic_operator_t) :: beam_model_t
        !> Number of nodes.
        integer :: n_nodes = 0
        !> Number of elements.
        integer :: n_elements = 0
        !> Equation number of each DOF (3, n_nodes), 0 if fixed.
        integer, allocatable :: eq(:, :)
        !> Node ids of the deck (for messages), size n_nodes.
        integer, allocatable :: node_id(:)
        !> Node coordinates [m].
        real(wp), allocatable :: x(:), y(:)
        !> Connectivity (2, n_elements).
        integer, allocatable :: conn(:, :)
        !> Element length [m], direction cosines of the axis.
        real(wp), allocatable :: length(:), cosine(:), sine(:)
        !> Element rigidities E*A [N], E*I [N.m^2] and mass per length rho*A [kg/m].
        real(wp), allocatable :: ea(:), ei(:), rho_a(:)
        !> Stiffness matrix on the free DOFs (band).
        type(band_spd_t) :: k
        !> Mass matrix on the free DOFs (band; diagonal when lumped).
        type(band_spd_t) :: m
        !> Nodal loads (value times function).
        type(beam_load_t), allocatable :: loads(:)
        !> Time functions referenced by the loads.
        type(time_function_slot_t), allocatable :: functions(:)
        !> Distributed loads, self-weight included: element of each (size n_element_loads).
        integer, allocatable :: eload_element(:)
        !> Time function of each distributed load (0 = constant 1).
        integer, allocatable :: eload_func(:)
        !> Consistent nodal forces and moments of each distributed load in global axes
        !> (6, n_element_loads), on all six DOFs of its element (fixed ones included, for the
        !> reactions); the self-weight is weighted by the Arlequin weight like the mass, the
        !> distributed loads of the deck are not.
        real(wp), allocatable :: eload_vector(:, :)
        !> Curvilinear abscissa of each node [m]: distance from node 1 along the elements
        !> (from the lowest node of each connected part); size n_nodes.
        real(wp), allocatable :: abscissa(:)
        !> True when mass, stiffness and self-weight were weighted by an Arlequin weight.
        logical :: weighted = .false.
        !> Weighted element stiffness matrices in global axes (6, 6, n_elements), kept for
        !> `reactions` (allocated only when weighted).
        real(wp), allocatable :: k_element(:, :, :)
    contains
        !> f(n_free) = external nodal forces at time t.
        procedure :: external_force
        !> ku = K u.
        procedure :: stiffness_times
        !> mv = M v.
        procedure :: mass_times
        !> cv = C v (Rayleigh).
        procedure :: damping_times
        !> True when C /= 0.
        procedure :: is_damped
        !> 1/2 u.K u.
        procedure :: strain_energy
        !> 1/2 v.M v.
        procedure :: kinetic_energy
        !> Free-DOF vector to (3, n_nodes), zeros on fixed DOFs.
        procedure :: expand
        !> (3, n_nodes) to free-DOF vector.
        procedure :: restrict
        !> Reactions (3, n_nodes) on fixed DOFs.
        procedure :: reactions
        !> 'node 3 (id 12), DOF w' for an equation number.
        procedure :: equation_label
        !> Error when a connected part of the frame can move as a rigid body.
        procedure :: check_supports
        !> Connected part of each node (its smallest node index).
        procedure :: part_roots
        !> Rigid-body motions of one part that its supports leave free.
        procedure :: part_rigid_motions
        !> Curvilinear abscissa at reduced coordinate xi of an element.
        procedure :: abscissa_at
        !> Band Cholesky factor of c_m M + c_k K.
        procedure :: factor_combination
        !> Diagonal of the (lumped) mass matrix.
        procedure :: mass_diagonal
        !> Largest eigenvalue of K phi = omega^2 M phi (band LAPACK).
        procedure :: largest_eigenvalue
    end type beam_model_t

    !> A band Cholesky factor as a `spd_factor_t`.
    type, extends(spd_factor_t) :: band_factor_t
        !> The factored band matrix.
        type(band_spd_t) :: a
    contains
        procedure :: solve_vec => band_factor_solve_vec
        procedure :: solve_mat => band_factor_solve_mat
    end type band_factor_t

contains

    !> Build the model from its description: checks, equation numbering, assembly of K and M.
    !> A model without enough supports is accepted here (explicit dynamics and modal analysis
    !> do not need it); the singular stiffness is reported when K is factored.
    !> With a weight, K, M and the self-weight are integrated with alpha(s) (Arlequin
    !> partition); elements where alpha = 0 get no mass nor stiffness. The nodal and distributed
    !> loads are applied in full (the disks carry no share of them).
    subroutine build_beam_model(config, model, error, weight)
        !> The frame description.
        type(beam_config_t), intent(in) :: config
        !> The model built.
        type(beam_model_t), intent(out) :: model
        !> Set when the description is invalid.
        type(error_t), allocatable, intent(out) :: error
        !> Arlequin weight alpha(s), s = `model%abscissa`; none = alpha = 1 everywhere.
        class(weight_function_t), intent(in), optional :: weight
        call check_mesh(config, error)
        if (allocated(error)) return
        call check_elements(config, error)
        if (allocated(error)) return
        call check_sections(config, error)
        if (allocated(error)) return
        call check_loads(config, error)
        if (allocated(error)) return
        call check_element_loads(config, error)
        if (allocated(error)) return
        call copy_geometry(config, model)
        call number_equations(config, model, error)
        if (allocated(error)) return
        if (allocated(config%mass_scheme)) then
            allocate (model%mass_scheme, source=config%mass_scheme)
        else
            allocate (consistent_mass_t :: model%mass_scheme)
        end if
        model%rayleigh_a0 = config%rayleigh_a0
        model%rayleigh_a1 = config%rayleigh_a1
        allocate (model%loads(0), model%functions(0))
        if (allocated(config%loads)) model%loads = config%loads
        if (allocated(config%functions)) model%functions = config%functions
        call compute_abscissa(model)
        if (present(weight)) then
            model%weighted = .true.
            call assemble(model, error, weight)
            call build_element_loads(config, model, weight)
        else
            call assemble(model, error)
            call build_element_loads(config, model)
        end if
    end subroutine build_beam_model

    !> Distributed loads refer to existing elements, directions and functions.
    subroutine check_element_loads(config, error)
        type(beam_config_t), intent(in) :: config
        type(error_t), allocatable, intent(out) :: error
        integer :: i, nf
        character(len=200) :: buf
        if (.not. allocated(config%element_loads)) return
        nf = 0
        if (allocated(config%functions)) nf = size(config%functions)
        do i = 1, size(config%element_loads)
            associate (ld => config%element_loads(i))
                if (ld%element < 1 .or. ld%element > size(config%conn, 2)) then
                    write (buf, '(a,i0,a,i0,a)') 'beam model: distributed load ', i, &
                        ' is on element ', ld%element, ', which does not exist'
                else if (ld%direction < load_x .or. ld%direction > load_transverse) then
                    write (buf, '(a,i0,a)') 'beam model: distributed load ', i, ' has no direction'
                else if (ld%func < 0 .or. ld%func > nf) then
                    write (buf, '(a,i0,a,i0,a)') 'beam model: distributed load ', i, &
                        ' uses time function ', ld%func, ', which is not defined'
                else
                    cycle
                end if
            end associate
            call make_error(error, trim(buf))
            return
        end do
    end subroutine check_element_loads

    !> Consistent nodal forces of the distributed loads, f = int N^T q ds, and of the
    !> self-weight rho A g, f = int alpha N^T q ds with a weight (Gauss, 6 points per piece
    !> between the weight's breakpoints: exact for a linear q times a cubic Hermite N times a
    !> piecewise cubic alpha), over each element, in global axes, on all six DOFs of the
    !> element. The distributed loads are not weighted (applied in full, see build_beam_model).
    subroutine build_element_loads(config, model, weight)
        type(beam_config_t), intent(in) :: config
        type(beam_model_t), intent(inout) :: model
        class(weight_function_t), intent(in), optional :: weight
        integer :: n_given, n, i, e
        real(wp) :: qa(2), qt(2)
        n_given = 0
        if (allocated(config%element_loads)) n_given = size(config%element_loads)
        n = n_given
        if (any(config%gravity /= 0.0_wp)) n = n + model%n_elements
        allocate (model%eload_element(n), model%eload_func(n), model%eload_vector(6, n))
        do i = 1, n_given
            associate (ld => config%element_loads(i))
                e = ld%element
                associate (c => model%cosine(e), s => model%sine(e))
                    select case (ld%direction)
                    case (load_x)
                        qa = c*ld%q
                        qt = -s*ld%q
                    case (load_y)
                        qa = s*ld%q
                        qt = c*ld%q
                    case (load_axial)
                        qa = ld%q
                        qt = 0.0_wp
                    case default
                        qa = 0.0_wp
                        qt = ld%q
                    end select
                end associate
                model%eload_element(i) = e
                model%eload_func(i) = ld%func
                model%eload_vector(:, i) = element_load_vector(model, e, qa, qt)
            end associate
        end do
        do e = 1, n - n_given
            i = n_given + e
            ! Self-weight rho A g per unit length, in local components of the element axis.
            qa = model%rho_a(e)*(model%cosine(e)*config%gravity(1) + model%sine(e)*config%gravity(2))
            qt = model%rho_a(e)*(-model%sine(e)*config%gravity(1) + model%cosine(e)*config%gravity(2))
            model%eload_element(i) = e
            model%eload_func(i) = 0
            model%eload_vector(:, i) = element_load_vector(model, e, qa, qt, weight)
        end do
    end subroutine build_element_loads

    !> Consistent nodal forces in global axes (6) of a load linear along element e, with axial
    !> components qa and transverse components qt at its two ends [N/m]: the local vector is
    !> int alpha [Na qa; Nh qt] ds (Na linear, Nh Hermite), turned to global axes by T^T.
    function element_load_vector(model, e, qa, qt, weight) result(f)
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: e
        real(wp), intent(in) :: qa(2), qt(2)
        class(weight_function_t), intent(in), optional :: weight
        real(wp) :: f(6)
        real(wp), allocatable :: cuts(:)
        real(wp) :: fl(6), xi, dxi, dw, l, na(2), nh(4)
        integer :: p, g
        l = model%length(e)
        if (present(weight)) then
            cuts = element_cuts(model, e, weight)
        else
            cuts = [0.0_wp, 1.0_wp]
        end if
        fl = 0.0_wp
        do p = 1, size(cuts) - 1
            dxi = cuts(p + 1) - cuts(p)
            do g = 1, 6
                xi = cuts(p) + dxi*gauss_t(g)
                dw = gauss_w(g)*dxi*l
                if (present(weight)) dw = dw*weight%value(model%abscissa_at(e, xi))
                na = [1.0_wp - xi, xi]
                nh = hermite_shape(xi, l)
                fl([1, 4]) = fl([1, 4]) + dw*dot_product(na, qa)*na
                fl([2, 3, 5, 6]) = fl([2, 3, 5, 6]) + dw*dot_product(na, qt)*nh
            end do
        end do
        f = matmul(transpose(rotation_matrix(model%cosine(e), model%sine(e))), fl)
    end function element_load_vector

    !> Node label for messages: 'node 3 (id 12)'.
    function node_label(config, i) result(label)
        type(beam_config_t), intent(in) :: config
        integer, intent(in) :: i
        character(len=:), allocatable :: label
        character(len=40) :: buf
        write (buf, '(a,i0)') 'node ', i
        if (allocated(config%node_id)) then
            if (size(config%node_id) >= i) write (buf, '(a,i0,a,i0,a)') 'node ', i, &
                ' (id ', config%node_id(i), ')'
        end if
        label = trim(buf)
    end function node_label

    !> Sizes and presence of the arrays.
    subroutine check_mesh(config, error)
        type(beam_config_t), intent(in) :: config
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        if (.not. (allocated(config%x) .and. allocated(config%y))) then
            call make_error(error, 'beam model: no nodes given (at least 2 are needed)')
            return
        end if
        n = size(config%x)
        if (n < 2 .or. size(config%y) /= n) then
            call make_error(error, 'beam model: at least 2 nodes with x and y are needed')
        else if (.not. allocated(config%conn)) then
            call make_error(error, 'beam model: no elements given (at least 1 is needed)')
        else if (size(config%conn, 1) /= 2 .or. size(config%conn, 2) < 1) then
            call make_error(error, 'beam model: at least 1 element with 2 nodes is needed')
        else if (.not. allocated(config%elem_section)) then
            call make_error(error, 'beam model: elements have no section')
        else if (size(config%elem_section) /= size(config%conn, 2)) then
            call make_error(error, 'beam model: one section index per element is needed')
        else if (.not. allocated(config%sections)) then
            call make_error(error, 'beam model: no section defined')
        end if
        if (allocated(error) .or. .not. allocated(config%fixed)) return
        if (any(shape(config%fixed) /= [3, n])) &
            call make_error(error, 'beam model: supports array must be (3, n_nodes)')
    end subroutine check_mesh

    !> Node indices, lengths and section indices of the elements.
    subroutine check_elements(config, error)
        type(beam_config_t), intent(in) :: config
        type(error_t), allocatable, intent(out) :: error
        integer :: e, n1, n2, n
        real(wp) :: span, length
        character(len=200) :: buf
        n = size(config%x)
        span = hypot(maxval(config%x) - minval(config%x), maxval(config%y) - minval(config%y))
        do e = 1, size(config%conn, 2)
            n1 = config%conn(1, e)
            n2 = config%conn(2, e)
            if (min(n1, n2) < 1 .or. max(n1, n2) > n) then
                write (buf, '(a,i0,a,i0,a)') 'beam model: element ', e, &
                    ' refers to a node outside 1..', n, ''
                call make_error(error, trim(buf))
                return
            end if
            length = hypot(config%x(n2) - config%x(n1), config%y(n2) - config%y(n1))
            ! Zero up to rounding of the coordinates (relative to the size of the model).
            if (length <= relative_roundoff*span) then
                write (buf, '(a,i0,a)') 'beam model: element ', e, ' has zero length ('// &
                    node_label(config, n1)//' and '//node_label(config, n2)// &
                    ' are at the same place); remove it or move a node'
                call make_error(error, trim(buf))
                return
            end if
            if (config%elem_section(e) < 1 .or. config%elem_section(e) > size(config%sections)) then
                write (buf, '(a,i0,a,i0,a,i0,a)') 'beam model: element ', e, ' uses section ', &
                    config%elem_section(e), ' but sections are numbered 1..', &
                    size(config%sections), ''
                call make_error(error, trim(buf))
                return
            end if
        end do
    end subroutine check_elements

    !> Material and section properties must be positive.
    subroutine check_sections(config, error)
        type(beam_config_t), intent(in) :: config
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        character(len=200) :: buf
        type(beam_section_t) :: s
        do i = 1, size(config%sections)
            s = config%sections(i)
            if (.not. (s%young > 0 .and. s%density > 0 .and. s%area > 0 .and. s%inertia > 0)) then
                write (buf, '(a,i0,a)') 'beam model: section ', i, ' needs young, density, '// &
                    'area and inertia > 0'
                call make_error(error, trim(buf))
                return
            end if
        end do
        if (config%rayleigh_a0 < 0 .or. config%rayleigh_a1 < 0) &
            call make_error(error, 'beam model: Rayleigh damping coefficients must be >= 0')
    end subroutine check_sections

    !> Loads refer to existing nodes, DOFs and functions, and not to a fixed DOF.
    subroutine check_loads(config, error)
        type(beam_config_t), intent(in) :: config
        type(error_t), allocatable, intent(out) :: error
        integer :: i, nf
        character(len=200) :: buf
        type(beam_load_t) :: ld
        if (.not. allocated(config%loads)) return
        nf = 0
        if (allocated(config%functions)) nf = size(config%functions)
        do i = 1, size(config%loads)
            ld = config%loads(i)
            if (ld%node < 1 .or. ld%node > size(config%x)) then
                write (buf, '(a,i0,a,i0,a)') 'beam model: load ', i, ' is on node ', ld%node, &
                    ', which does not exist'
            else if (ld%dof < 1 .or. ld%dof > 3) then
                write (buf, '(a,i0,a)') 'beam model: load ', i, ' has a DOF not in 1..3'
            else if (ld%func < 0 .or. ld%func > nf) then
                write (buf, '(a,i0,a,i0,a)') 'beam model: load ', i, ' uses time function ', &
                    ld%func, ', which is not defined'
            else if (is_fixed(config, ld%node, ld%dof)) then
                write (buf, '(a,i0,a)') 'beam model: load ', i, ' acts on fixed DOF '// &
                    trim(dof_names(ld%dof))//' of '//node_label(config, ld%node)// &
                    '; a load on a support does nothing: remove it or free the DOF'
            else
                cycle
            end if
            call make_error(error, trim(buf))
            return
        end do
    end subroutine check_loads

    !> True when DOF dof of node i is fixed.
    pure logical function is_fixed(config, i, dof)
        type(beam_config_t), intent(in) :: config
        integer, intent(in) :: i, dof
        is_fixed = .false.
        if (allocated(config%fixed)) is_fixed = config%fixed(dof, i)
    end function is_fixed

    !> Nodes, connectivity, element geometry and rigidities.
    subroutine copy_geometry(config, model)
        type(beam_config_t), intent(in) :: config
        type(beam_model_t), intent(inout) :: model
        integer :: e, n1, n2, i
        real(wp) :: dx, dy
        model%n_nodes = size(config%x)
        model%n_elements = size(config%conn, 2)
        model%x = config%x
        model%y = config%y
        model%conn = config%conn
        if (allocated(config%node_id)) then
            model%node_id = config%node_id
        else
            model%node_id = [(i, i=1, model%n_nodes)]
        end if
        allocate (model%length(model%n_elements), model%cosine(model%n_elements))
        allocate (model%sine(model%n_elements), model%ea(model%n_elements))
        allocate (model%ei(model%n_elements), model%rho_a(model%n_elements))
        do e = 1, model%n_elements
            n1 = config%conn(1, e)
            n2 = config%conn(2, e)
            dx = config%x(n2) - config%x(n1)
            dy = config%y(n2) - config%y(n1)
            model%length(e) = hypot(dx, dy)
            model%cosine(e) = dx/model%length(e)
            model%sine(e) = dy/model%length(e)
            associate (s => config%sections(config%elem_section(e)))
                model%ea(e) = s%young*s%area
                model%ei(e) = s%young*s%inertia
                model%rho_a(e) = s%density*s%area
            end associate
        end do
    end subroutine copy_geometry

    !> Equation numbers node by node; fails when every DOF is fixed.
    subroutine number_equations(config, model, error)
        type(beam_config_t), intent(in) :: config
        type(beam_model_t), intent(inout) :: model
        type(error_t), allocatable, intent(out) :: error
        integer :: i, d
        allocate (model%eq(3, model%n_nodes), source=0)
        model%n_free = 0
        do i = 1, model%n_nodes
            do d = 1, 3
                if (is_fixed(config, i, d)) cycle
                model%n_free = model%n_free + 1
                model%eq(d, i) = model%n_free
            end do
        end do
        if (model%n_free == 0) &
            call make_error(error, 'beam model: every DOF is fixed, there is nothing to solve')
    end subroutine number_equations

    !> Equation numbers of the six DOFs of element e (0 = fixed).
    pure function element_dofs(model, e) result(dofs)
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: e
        integer :: dofs(6)
        dofs(1:3) = model%eq(:, model%conn(1, e))
        dofs(4:6) = model%eq(:, model%conn(2, e))
    end function element_dofs

    !> Assemble the band K and M on the free DOFs (weighted when a weight is given).
    subroutine assemble(model, error, weight)
        type(beam_model_t), intent(inout) :: model
        type(error_t), allocatable, intent(out) :: error
        class(weight_function_t), intent(in), optional :: weight
        integer :: e, a, b, kd, p
        integer :: dofs(6)
        integer, allocatable :: rows(:), cols(:)
        real(wp) :: kg(6, 6), mg(6, 6), ml(6)
        real(wp), allocatable :: values(:)
        kd = 0
        do e = 1, model%n_elements
            dofs = element_dofs(model, e)
            if (count(dofs > 0) > 1) kd = max(kd, maxval(dofs) - minval(dofs, dofs > 0))
        end do
        call model%k%init(model%n_free, kd)
        call model%m%init(model%n_free, merge(0, kd, model%mass_scheme%is_diagonal()))
        if (present(weight)) allocate (model%k_element(6, 6, model%n_elements))
        do e = 1, model%n_elements
            dofs = element_dofs(model, e)
            if (present(weight)) then
                call weighted_element(model, e, weight, kg, mg, ml)
                model%k_element(:, :, e) = kg
            else
                associate (c => model%cosine(e), s => model%sine(e), l => model%length(e))
                    kg = to_global(element_stiffness(model%ea(e), model%ei(e), l), c, s)
                    mg = to_global(element_mass_consistent(model%rho_a(e), l), c, s)
                    ml = element_mass_lumped(model%rho_a(e), l)
                end associate
            end if
            do b = 1, 6
                if (dofs(b) == 0) cycle
                do a = 1, 6
                    if (dofs(a) == 0) cycle
                    call model%k%add(dofs(a), dofs(b), kg(a, b))
                end do
            end do
            call model%mass_scheme%element_entries(mg, ml, rows, cols, values)
            do p = 1, size(values)
                if (dofs(rows(p)) == 0 .or. dofs(cols(p)) == 0) cycle
                call model%m%add(dofs(rows(p)), dofs(cols(p)), values(p))
            end do
        end do
        if (model%k%out_of_band .or. model%m%out_of_band) &
            call make_internal_error(error, 'beam model assembly', 'an entry fell outside the band (bandwidth computed too small)')
    end subroutine assemble

    !> Weighted element matrices in global axes: kg = int alpha B^T D B ds, mg = int alpha
    !> rho A N^T N ds (Gauss, 6 points per piece between breakpoints of alpha), and the
    !> lumped diagonal ml: translations int alpha rho A N_i ds (linear N_i, the same in x and
    !> y so that it does not depend on the axes), rotations the consistent diagonal scaled as
    !> in HRZ (by the transverse mass over the sum of the transverse diagonal); with alpha = 1
    !> these are the unweighted matrices.
    subroutine weighted_element(model, e, weight, kg, mg, ml)
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: e
        class(weight_function_t), intent(in) :: weight
        real(wp), intent(out) :: kg(6, 6), mg(6, 6), ml(6)
        real(wp), allocatable :: cuts(:)
        real(wp) :: kl(6, 6), m(6, 6), xi, dxi, dw, l, na(2), nh(4), bh(4), total, scale
        integer :: p, g
        integer, parameter :: ax(2) = [1, 4], tr(4) = [2, 3, 5, 6]
        l = model%length(e)
        cuts = element_cuts(model, e, weight)
        kl = 0.0_wp
        m = 0.0_wp
        do p = 1, size(cuts) - 1
            dxi = cuts(p + 1) - cuts(p)
            do g = 1, 6
                xi = cuts(p) + dxi*gauss_t(g)
                ! alpha ds at this Gauss point.
                dw = weight%value(model%abscissa_at(e, xi))*gauss_w(g)*dxi*l
                na = [1.0_wp - xi, xi]
                nh = hermite_shape(xi, l)
                ! Curvatures d2N/dx2 of the Hermite functions.
                bh = [(12*xi - 6)/l**2, (6*xi - 4)/l, (6 - 12*xi)/l**2, (6*xi - 2)/l]
                kl(ax, ax) = kl(ax, ax) + dw*model%ea(e)/l**2* &
                             reshape([1.0_wp, -1.0_wp, -1.0_wp, 1.0_wp], [2, 2])
                kl(tr, tr) = kl(tr, tr) + dw*model%ei(e)*outer(bh, bh)
                m(ax, ax) = m(ax, ax) + dw*model%rho_a(e)*outer(na, na)
                m(tr, tr) = m(tr, tr) + dw*model%rho_a(e)*outer(nh, nh)
            end do
        end do
        kg = to_global(kl, model%cosine(e), model%sine(e))
        mg = to_global(m, model%cosine(e), model%sine(e))
        ! Lumped: the row sums of the axial mass (= int alpha rho A N_i ds) on both
        ! translations, the HRZ-scaled consistent rotational diagonal.
        ml(1) = m(1, 1) + m(1, 4)
        ml(4) = m(4, 1) + m(4, 4)
        ml(2) = ml(1)
        ml(5) = ml(4)
        total = ml(1) + ml(4)
        scale = 0.0_wp
        if (m(2, 2) + m(5, 5) > 0) scale = total/(m(2, 2) + m(5, 5))
        ml(3) = m(3, 3)*scale
        ml(6) = m(6, 6)*scale
    end subroutine weighted_element

    !> Outer product a b^T.
    pure function outer(a, b) result(c)
        real(wp), intent(in) :: a(:), b(:)
        real(wp) :: c(size(a), size(b))
        c = spread(a, 2, size(b))*spread(b, 1, size(a))
    end function outer

    !> Reduced coordinates 0 = c_1 < ... < c_n = 1 of an element cut at the breakpoints of
    !> the weight that fall strictly inside it.
    function element_cuts(model, e, weight) result(cuts)
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: e
        class(weight_function_t), intent(in) :: weight
        real(wp), allocatable :: cuts(:)
        real(wp), allocatable :: bp(:)
        real(wp) :: s1, s2, xi
        integer :: i, j
        ! Cuts closer than this to an end or to each other are dropped: such pieces carry
        ! nothing at double precision.
        real(wp), parameter :: eps = relative_roundoff
        s1 = model%abscissa(model%conn(1, e))
        s2 = model%abscissa(model%conn(2, e))
        bp = weight%breakpoints()
        cuts = [0.0_wp]
        if (s2 /= s1) then
            do i = 1, size(bp)
                xi = (bp(i) - s1)/(s2 - s1)
                if (xi > eps .and. xi < 1 - eps) cuts = [cuts, xi]
            end do
        end if
        ! Sort (breakpoints are increasing in s, but s may decrease along the element).
        call sort_in_place(cuts)
        ! Drop coincident breakpoints, then close with 1.
        j = 1
        do i = 2, size(cuts)
            if (cuts(i) - cuts(j) <= eps) cycle
            j = j + 1
            cuts(j) = cuts(i)
        end do
        cuts = [cuts(1:j), 1.0_wp]
    end function element_cuts

    !> Curvilinear abscissa of every node: shortest distance along the elements from the
    !> lowest-numbered node of its connected part (node 1 for a connected frame); for a
    !> single chain of elements this is the arc length from node 1.
    subroutine compute_abscissa(model)
        type(beam_model_t), intent(inout) :: model
        integer :: comp(model%n_nodes), e, n1, n2, i
        logical :: changed
        call component_roots(model, comp)
        allocate (model%abscissa(model%n_nodes), source=huge(1.0_wp))
        do i = 1, model%n_nodes
            if (comp(i) == i) model%abscissa(i) = 0.0_wp
        end do
        ! Bellman-Ford relaxation over the elements (one sweep for elements in chain order).
        changed = .true.
        do while (changed)
            changed = .false.
            do e = 1, model%n_elements
                n1 = model%conn(1, e)
                n2 = model%conn(2, e)
                if (model%abscissa(n1) + model%length(e) < model%abscissa(n2)) then
                    model%abscissa(n2) = model%abscissa(n1) + model%length(e)
                    changed = .true.
                else if (model%abscissa(n2) + model%length(e) < model%abscissa(n1)) then
                    model%abscissa(n1) = model%abscissa(n2) + model%length(e)
                    changed = .true.
                end if
            end do
        end do
    end subroutine compute_abscissa

    !> Curvilinear abscissa [m] at reduced coordinate xi in [0, 1] of element e (linear
    !> between the abscissas of its nodes).
    pure real(wp) function abscissa_at(self, e, xi) result(s)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Element.
        integer, intent(in) :: e
        !> Reduced coordinate x/L from the element's first node.
        real(wp), intent(in) :: xi
        associate (s1 => self%abscissa(self%conn(1, e)), s2 => self%abscissa(self%conn(2, e)))
            s = s1 + xi*(s2 - s1)
        end associate
    end function abscissa_at

    !> External nodal forces at time t on the free DOFs: sum of value*function(t).
    subroutine external_force(self, t, f)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> Forces (n_free) [N, N.m].
        real(wp), intent(out) :: f(:)
        integer :: i, ieq, k, dofs(6)
        real(wp) :: scale
        f = 0.0_wp
        do i = 1, size(self%loads)
            ieq = self%eq(self%loads(i)%dof, self%loads(i)%node)
            if (ieq == 0) cycle
            scale = 1.0_wp
            if (self%loads(i)%func > 0) scale = self%functions(self%loads(i)%func)%fn%value(t)
            f(ieq) = f(ieq) + self%loads(i)%value*scale
        end do
        do i = 1, size(self%eload_element)
            scale = 1.0_wp
            if (self%eload_func(i) > 0) scale = self%functions(self%eload_func(i))%fn%value(t)
            dofs = element_dofs(self, self%eload_element(i))
            do k = 1, 6
                if (dofs(k) > 0) f(dofs(k)) = f(dofs(k)) + self%eload_vector(k, i)*scale
            end do
        end do
    end subroutine external_force

    !> ku = K u.
    subroutine stiffness_times(self, u, ku)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Displacements (n_free).
        real(wp), contiguous, intent(in) :: u(:)
        !> Elastic forces K u (n_free).
        real(wp), contiguous, intent(out) :: ku(:)
        call self%k%matvec(u, ku)
    end subroutine stiffness_times

    !> mv = M v.
    subroutine mass_times(self, v, mv)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Velocities or accelerations (n_free).
        real(wp), contiguous, intent(in) :: v(:)
        !> M v (n_free).
        real(wp), contiguous, intent(out) :: mv(:)
        call self%m%matvec(v, mv)
    end subroutine mass_times

    !> cv = C v = a0 M v + a1 K v.
    subroutine damping_times(self, v, cv)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Velocities (n_free).
        real(wp), contiguous, intent(in) :: v(:)
        !> Damping forces C v (n_free).
        real(wp), contiguous, intent(out) :: cv(:)
        call self%k%matvec(v, cv, alpha=self%rayleigh_a1)
        call self%m%matvec(v, cv, alpha=self%rayleigh_a0, beta=1.0_wp)
    end subroutine damping_times

    !> True when the Rayleigh damping is not zero.
    pure logical function is_damped(self)
        !> The model.
        class(beam_model_t), intent(in) :: self
        is_damped = self%rayleigh_a0 /= 0 .or. self%rayleigh_a1 /= 0
    end function is_damped

    !> Strain energy 1/2 u.K u [J].
    real(wp) function strain_energy(self, u)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Displacements (n_free).
        real(wp), contiguous, intent(in) :: u(:)
        real(wp) :: ku(size(u))
        call self%k%matvec(u, ku)
        strain_energy = 0.5_wp*dot_product(u, ku)
    end function strain_energy

    !> Kinetic energy 1/2 v.M v [J].
    real(wp) function kinetic_energy(self, v)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Velocities (n_free).
        real(wp), contiguous, intent(in) :: v(:)
        real(wp) :: mv(size(v))
        call self%m%matvec(v, mv)
        kinetic_energy = 0.5_wp*dot_product(v, mv)
    end function kinetic_energy

    !> Band Cholesky factor of c_m M + c_k K; M alone (c_k = 0) keeps the band of M.
    subroutine factor_combination(self, c_m, c_k, factor, error)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Coefficient of M.
        real(wp), intent(in) :: c_m
        !> Coefficient of K.
        real(wp), intent(in) :: c_k
        !> The factor.
        class(spd_factor_t), allocatable, intent(out) :: factor
        !> Set when the matrix is not positive definite.
        type(error_t), allocatable, intent(out) :: error
        type(band_factor_t), allocatable :: f
        allocate (f)
        if (c_k == 0 .and. c_m == 1) then
            f%a = self%m
        else
            call f%a%init(self%n_free, self%k%kd)
            call f%a%add_scaled(self%m, c_m)
            call f%a%add_scaled(self%k, c_k)
        end if
        call f%a%factor(error)
        call move_alloc(f, factor)
    end subroutine factor_combination

    !> x <- A^-1 x.
    subroutine band_factor_solve_vec(self, x, error)
        class(band_factor_t), intent(inout) :: self
        real(wp), contiguous, intent(inout) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        call self%a%solve(x, error)
    end subroutine band_factor_solve_vec

    !> X <- A^-1 X.
    subroutine band_factor_solve_mat(self, x, error)
        class(band_factor_t), intent(inout) :: self
        real(wp), contiguous, intent(inout) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        call self%a%solve(x, error)
    end subroutine band_factor_solve_mat

    !> Diagonal of the mass matrix (the whole matrix when lumped).
    subroutine mass_diagonal(self, d)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> M(i, i) (n_free).
        real(wp), intent(out) :: d(:)
        call self%m%diagonal(d)
    end subroutine mass_diagonal

    !> Largest eigenvalue of K phi = omega^2 M phi (dsbgvx).
    subroutine largest_eigenvalue(self, lambda_max, error)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> omega_max^2 [1/s^2].
        real(wp), intent(out) :: lambda_max
        !> Set on eigensolver failure.
        type(error_t), allocatable, intent(out) :: error
        call largest_generalized_eigenvalue(self%k, self%m, lambda_max, error)
    end subroutine largest_eigenvalue

    !> Free-DOF vector to nodal array d(3, n_nodes), zeros on fixed DOFs.
    pure subroutine expand(self, u_free, d)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Vector on the free DOFs (n_free).
        real(wp), intent(in) :: u_free(:)
        !> Nodal values (3, n_nodes).
        real(wp), intent(out) :: d(:, :)
        integer :: i, k
        do i = 1, self%n_nodes
            do k = 1, 3
                d(k, i) = 0.0_wp
                if (self%eq(k, i) > 0) d(k, i) = u_free(self%eq(k, i))
            end do
        end do
    end subroutine expand

    !> Nodal array d(3, n_nodes) to a free-DOF vector (values on fixed DOFs are dropped);
    !> an absent d (e.g. an unallocated array) gives zeros.
    pure subroutine restrict(self, d, u_free)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Nodal values (3, n_nodes).
        real(wp), intent(in), optional :: d(:, :)
        !> Vector on the free DOFs (n_free).
        real(wp), allocatable, intent(out) :: u_free(:)
        integer :: i, k
        allocate (u_free(self%n_free), source=0.0_wp)
        if (.not. present(d)) return
        do i = 1, self%n_nodes
            do k = 1, 3
                if (self%eq(k, i) > 0) u_free(self%eq(k, i)) = d(k, i)
            end do
        end do
    end subroutine restrict

    !> Support reactions r(3, n_nodes) = (K_full u - F)(t) on fixed DOFs, 0 on free DOFs
    !> (element-by-element product, no full matrix).
    subroutine reactions(self, u, t, r)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Displacements on the free DOFs (n_free).
        real(wp), intent(in) :: u(:)
        !> Time [s] of the loads.
        real(wp), intent(in) :: t
        !> Reactions (3, n_nodes) [N, N.m].
        real(wp), intent(out) :: r(:, :)
        real(wp) :: d(3, self%n_nodes), kg(6, 6), fe(6), scale
        integer :: e, n1, n2, i
        call self%expand(u, d)
        r = 0.0_wp
        do e = 1, self%n_elements
            n1 = self%conn(1, e)
            n2 = self%conn(2, e)
            if (allocated(self%k_element)) then
                kg = self%k_element(:, :, e)
            else
                kg = to_global(element_stiffness(self%ea(e), self%ei(e), self%length(e)), &
                               self%cosine(e), self%sine(e))
            end if
            fe = matmul(kg, [d(:, n1), d(:, n2)])
            r(:, n1) = r(:, n1) + fe(1:3)
            r(:, n2) = r(:, n2) + fe(4:6)
        end do
        ! Loads on supports are refused at build time; kept here so r = K u - F holds anyway.
        do i = 1, size(self%loads)
            associate (ld => self%loads(i))
                scale = 1.0_wp
                if (ld%func > 0) scale = self%functions(ld%func)%fn%value(t)
                r(ld%dof, ld%node) = r(ld%dof, ld%node) - ld%value*scale
            end associate
        end do
        ! Distributed loads: their consistent forces on fixed DOFs go to the supports.
        do i = 1, size(self%eload_element)
            scale = 1.0_wp
            if (self%eload_func(i) > 0) scale = self%functions(self%eload_func(i))%fn%value(t)
            n1 = self%conn(1, self%eload_element(i))
            n2 = self%conn(2, self%eload_element(i))
            r(:, n1) = r(:, n1) - self%eload_vector(1:3, i)*scale
            r(:, n2) = r(:, n2) - self%eload_vector(4:6, i)*scale
        end do
        where (self%eq > 0) r = 0.0_wp
    end subroutine reactions

    !> Label of equation ieq for messages: 'node 3 (id 12), DOF w'.
    function equation_label(self, ieq) result(label)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Equation number (1..n_free).
        integer, intent(in) :: ieq
        character(len=:), allocatable :: label
        character(len=80) :: buf
        integer :: loc(2)
        label = 'an unknown DOF'
        if (.not. any(self%eq == ieq) .or. ieq < 1) return
        loc = findloc(self%eq, ieq)
        write (buf, '(a,i0,a,i0,a)') 'node ', loc(2), ' (id ', self%node_id(loc(2)), '), DOF '
        label = trim(buf)//' '//trim(dof_names(loc(1)))
    end function equation_label

    !> Error when some connected part of the frame is not held against rigid-body motion
    !> (x and y translation, rotation): exact test on the geometry of the supports, free of
    !> the rounding that blurs small pivots of a singular K. Each part needs fixed DOFs whose
    !> rigid-body rows (see `rigid_row`) have rank 3.
    subroutine check_supports(self, error)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> Set when a part can move freely.
        type(error_t), allocatable, intent(out) :: error
        integer :: comp(self%n_nodes), i, c, d
        real(wp) :: centre(2, self%n_nodes), gram(3, 3, self%n_nodes), row(3)
        character(len=160) :: buf
        call component_roots(self, comp)
        centre = 0.0_wp
        do i = 1, self%n_nodes
            centre(:, comp(i)) = centre(:, comp(i)) + [self%x(i), self%y(i)]
        end do
        do c = 1, self%n_nodes
            if (comp(c) == c) centre(:, c) = centre(:, c)/count(comp == c)
        end do
        gram = 0.0_wp
        do i = 1, self%n_nodes
            c = comp(i)
            do d = 1, 3
                if (self%eq(d, i) /= 0) cycle
                row = rigid_row(d, self%x(i) - centre(1, c), self%y(i) - centre(2, c))
                gram(:, :, c) = gram(:, :, c) + spread(row, 2, 3)*spread(row, 1, 3)
            end do
        end do
        do c = 1, self%n_nodes
            if (comp(c) /= c .or. full_rank(gram(:, :, c))) cycle
            write (buf, '(a,i0,a,i0,a)') 'node ', c, ' (id ', self%node_id(c), ')'
            call make_error(error, 'stiffness matrix is singular: the part of the frame '// &
                            'that contains '//trim(buf)//' can move as a rigid body (its '// &
                            'supports do not hold x, y and rotation); fix more DOFs (supports)'// &
                            coincident_hint(c))
            return
        end do
    contains
        !> When a node of part c lies where a node of another part lies, elements meant to meet
        !> there most likely got two node ids: say which (the first pair found).
        function coincident_hint(c) result(hint)
            integer, intent(in) :: c
            character(len=:), allocatable :: hint
            character(len=160) :: pair
            real(wp) :: tol
            integer :: i, j
            hint = ''
            ! a pairwise search, on the error path only: skipped beyond 2e4 nodes (4e8 pairs)
            if (self%n_nodes > 20000) return
            tol = 1.0e-12_wp*max(maxval(abs(self%x)), maxval(abs(self%y)), tiny(1.0_wp))
            do i = 1, self%n_nodes
                if (comp(i) /= c) cycle
                do j = 1, self%n_nodes
                    if (comp(j) == c) cycle
                    if (abs(self%x(i) - self%x(j)) > tol .or. abs(self%y(i) - self%y(j)) > tol) cycle
                    write (pair, '(a,i0,a,i0,a)') '; or join the parts: node id ', self%node_id(i), &
                        ' lies where node id ', self%node_id(j), &
                        ' of another part does, and elements connect only through a shared node id'
                    hint = trim(pair)
                    return
                end do
            end do
        end function coincident_hint
    end subroutine check_supports

    !> Connected part of each node: the smallest node index of its part (elements join nodes).
    pure function part_roots(self) result(comp)
        !> The model.
        class(beam_model_t), intent(in) :: self
        integer :: comp(self%n_nodes)
        call component_roots(self, comp)
    end function part_roots

    !> The rigid-body motions of the part whose smallest node index is `root` that its supports
    !> allow: the combinations of the part's x and y translations and its rotation about its
    !> centre that move none of its fixed DOFs. They are the part's motions without strain
    !> energy (K's null space there: an Euler-Bernoulli element strains under any other
    !> motion). Columns on the free DOFs, zero outside the part; none for a part that its
    !> supports hold. The combinations are the null space of the Gram matrix of the fixed DOFs'
    !> rows of the three motions, the rotation scaled by the part's radius so that the three
    !> columns are comparable: the eigenvectors of eigenvalues at most singular_ratio times its
    !> trace (exact dependence rounds to ~1e-16 of it; all three for a part without supports).
    function part_rigid_motions(self, comp, root, error) result(motions)
        !> The model.
        class(beam_model_t), intent(in) :: self
        !> The parts, from `part_roots`.
        integer, intent(in) :: comp(:)
        !> The part (its smallest node index).
        integer, intent(in) :: root
        !> Set on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        !> The free rigid-body motions (n_free, 0 to 3).
        real(wp), allocatable :: motions(:, :)
        real(wp) :: centre(2), radius, gram(3, 3), row(3), identity(3, 3)
        real(wp), allocatable :: w(:), v(:, :)
        integer, allocatable :: nodes(:)
        integer :: i, d, k, n_null
        nodes = pack([(i, i=1, self%n_nodes)], comp == root)
        centre = [sum(self%x(nodes)), sum(self%y(nodes))]/size(nodes)
        radius = maxval(hypot(self%x(nodes) - centre(1), self%y(nodes) - centre(2)))
        if (.not. radius > 0) radius = 1.0_wp
        gram = 0.0_wp
        do k = 1, size(nodes)
            i = nodes(k)
            do d = 1, 3
                if (self%eq(d, i) /= 0) cycle
                row = scaled_row(i, d)
                gram = gram + spread(row, 2, 3)*spread(row, 1, 3)
            end do
        end do
        identity = 0.0_wp
        do d = 1, 3
            identity(d, d) = 1.0_wp
        end do
        call dense_generalized_eigen(gram, identity, w, v, error)
        if (allocated(error)) return
        n_null = count(w <= singular_ratio*(gram(1, 1) + gram(2, 2) + gram(3, 3)))
        allocate (motions(self%n_free, n_null), source=0.0_wp)
        do k = 1, size(nodes)
            i = nodes(k)
            do d = 1, 3
                if (self%eq(d, i) == 0) cycle
                motions(self%eq(d, i), :) = matmul(scaled_row(i, d), v(:, 1:n_null))
            end do
        end do
    contains
        !> DOF d of node i in the three motions (x, y translation, rotation of 1/radius).
        pure function scaled_row(i, d) result(r)
            integer, intent(in) :: i, d
            real(wp) :: r(3)
            r = rigid_row(d, self%x(i) - centre(1), self%y(i) - centre(2))
            r(3) = r(3)/radius
        end function scaled_row
    end function part_rigid_motions

    !> Smallest node index of the connected part of each node (union-find over elements).
    pure subroutine component_roots(self, comp)
        type(beam_model_t), intent(in) :: self
        integer, intent(out) :: comp(:)
        integer :: parent(self%n_nodes), e, a, b, i
        parent = [(i, i=1, self%n_nodes)]
        do e = 1, self%n_elements
            a = root(self%conn(1, e))
            b = root(self%conn(2, e))
            parent(max(a, b)) = min(a, b)
        end do
        do i = 1, self%n_nodes
            comp(i) = root(i)
        end do
    contains
        pure integer function root(i0) result(r)
            integer, intent(in) :: i0
            r = i0
            do while (parent(r) /= r)
                r = parent(r)
            end do
        end function root
    end subroutine component_roots

    !> Value of DOF d at a node at (dx, dy) from the centre in the three rigid-body motions
    !> (x translation, y translation, unit rotation about the centre).
    pure function rigid_row(d, dx, dy) result(row)
        integer, intent(in) :: d
        real(wp), intent(in) :: dx, dy
        real(wp) :: row(3)
        select case (d)
        case (1)
            row = [1.0_wp, 0.0_wp, -dy]
        case (2)
            row = [0.0_wp, 1.0_wp, dx]
        case default
            row = [0.0_wp, 0.0_wp, 1.0_wp]
        end select
    end function rigid_row

    !> Rank 3 test of a 3x3 Gram matrix: det(G)/prod(diag G) is 1 for orthogonal rows, 0 for
    !> rank < 3, and does not depend on the scale of each column; singular_ratio separates exact
    !> zero (rounding ~ 1e-16) from nearly aligned supports (e.g. a roller 1e-6 L from a pin).
    pure logical function full_rank(g)
        real(wp), intent(in) :: g(3, 3)
        real(wp) :: det
        full_rank = .false.
        if (any([g(1, 1), g(2, 2), g(3, 3)] <= 0)) return
        det = g(1, 1)*(g(2, 2)*g(3, 3) - g(2, 3)*g(3, 2)) &
              - g(1, 2)*(g(2, 1)*g(3, 3) - g(2, 3)*g(3, 1)) &
              + g(1, 3)*(g(2, 1)*g(3, 2) - g(2, 2)*g(3, 1))
        full_rank = det > singular_ratio*g(1, 1)*g(2, 2)*g(3, 3)
    end function full_rank
end module fem_beam_model
