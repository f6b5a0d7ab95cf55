!> Plain description of a planar Euler-Bernoulli frame, filled by the deck reader
!> (driver/config) and turned into a `beam_model_t` by the FE constructor.
!>
!> Nodes are numbered 1..n_nodes here (deck ids are kept in `node_id` for output).
!> DOFs per node: 1 = u (axial/x), 2 = w (transverse/y), 3 = theta (rotation about z).
module fem_beam_config
    use core_kinds, only: wp
    use core_timefunc, only: time_function_slot_t
    use fem_mass_scheme, only: mass_scheme_t
    implicit none
    private
    public :: beam_section_t, beam_load_t, beam_config_t, dof_u, dof_w, dof_theta
    public :: beam_element_load_t, load_x, load_y, load_axial, load_transverse

    !> Index of the x displacement DOF of a node.
    integer, parameter :: dof_u = 1
    !> Index of the y displacement DOF of a node.
    integer, parameter :: dof_w = 2
    !> Index of the rotation DOF of a node.
    integer, parameter :: dof_theta = 3

    !> Direction of a distributed load: global x (per unit length of the element).
    integer, parameter :: load_x = 1
    !> Direction of a distributed load: global y (per unit length of the element).
    integer, parameter :: load_y = 2
    !> Direction of a distributed load: along the element axis, from its node 1 to its node 2.
    integer, parameter :: load_axial = 3
    !> Direction of a distributed load: across the element axis (the axis turned by +90 deg),
    !> the direction of the local w.
    integer, parameter :: load_transverse = 4

    !> Cross-section and material of a group of elements (SI units).
    type :: beam_section_t
        !> Young's modulus [Pa].
        real(wp) :: young = 0.0_wp
        !> Density [kg/m^3].
        real(wp) :: density = 0.0_wp
        !> Cross-section area [m^2].
        real(wp) :: area = 0.0_wp
        !> Second moment of area [m^4].
        real(wp) :: inertia = 0.0_wp
    end type beam_section_t

    !> A nodal load: value times a time function, on one DOF of one node.
    type :: beam_load_t
        !> Node index (1..n_nodes).
        integer :: node = 0
        !> DOF (dof_u, dof_w or dof_theta).
        integer :: dof = 0
        !> Amplitude [N or N.m].
        real(wp) :: value = 0.0_wp
        !> Index into `beam_config_t%functions` (0 = constant 1).
        integer :: func = 0
    end type beam_load_t

    !> A distributed load on one element, linear between its two ends, times a time function.
    type :: beam_element_load_t
        !> Element index (1..n_elements).
        integer :: element = 0
        !> Direction: load_x, load_y, load_axial or load_transverse.
        integer :: direction = 0
        !> Intensity at the element's node 1 and node 2 [N/m].
        real(wp) :: q(2) = 0.0_wp
        !> Index into `beam_config_t%functions` (0 = constant 1).
        integer :: func = 0
    end type beam_element_load_t

    !> Everything needed to build a beam model.
    type :: beam_config_t
        !> Node coordinates [m], size n_nodes.
        real(wp), allocatable :: x(:), y(:)
        !> Node ids as given in the deck (for output), size n_nodes.
        integer, allocatable :: node_id(:)
        !> Element connectivity (2, n_elements), node indices.
        integer, allocatable :: conn(:, :)
        !> Section index of each element, size n_elements.
        integer, allocatable :: elem_section(:)
        !> Sections.
        type(beam_section_t), allocatable :: sections(:)
        !> How the element masses enter: consistent or lumped (HRZ); unallocated: consistent.
        class(mass_scheme_t), allocatable :: mass_scheme
        !> Fixed DOFs (3, n_nodes).
        logical, allocatable :: fixed(:, :)
        !> Nodal loads.
        type(beam_load_t), allocatable :: loads(:)
        !> Time functions referenced by loads.
        type(time_function_slot_t), allocatable :: functions(:)
        !> Distributed loads on elements (consistent nodal forces and moments).
        type(beam_element_load_t), allocatable :: element_loads(:)
        !> Gravity acceleration (gx, gy) [m/s^2]: self-weight rho A g on every element.
        real(wp) :: gravity(2) = 0.0_wp
        !> Rayleigh damping C = a0 M + a1 K: mass coefficient [1/s].
        real(wp) :: rayleigh_a0 = 0.0_wp
        !> Rayleigh damping stiffness coefficient [s].
        real(wp) :: rayleigh_a1 = 0.0_wp
    end type beam_config_t
end module fem_beam_config
