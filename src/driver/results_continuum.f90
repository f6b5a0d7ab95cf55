!> The /continuum group of a results file (layout in doc/output.md) and the XDMF file next to it.
!>
!> /continuum/mesh: coordinates (2, n_nodes), connectivity (4, n_elements; 1-based, 0 beyond
!> a triangle's 3 nodes), kind (1 = T3, 2 = Q4: the kind ids of fem_element_registry),
!> topology (the 0-based XDMF connectivity: (3 or 4, n_elements) for one kind of element, a
!> flat mixed list otherwise; the topology names and codes are the element kinds');
!> material (n_elements: the element's material, 1-based index into /continuum/materials);
!> /continuum/materials/{young, poisson, density, thickness, plane_strain} (one value per
!> `material` record of the deck, in deck order; plane_strain 1 for plane strain, 0 for plane
!> stress); /continuum/sets/{nodes,elements}/<name> (1-based indices) and
!> /continuum/sets/edges/<name> (2, n_edges). A static run writes
!> /continuum/static/{displacement (2, n_nodes), stress (3, n_elements: xx, yy, xy at element
!> centres), stress_zz and von_mises (n_elements: sigma_zz and the von Mises stress of those
!> centre stresses, fem_elastic2d), reactions (2, n_nodes: K u - f on the prescribed dofs, N;
!> 0 on the free ones), strain_energy}; a modal run
!> /continuum/modal/{omega, frequency, shapes (2, n_nodes, n_modes)}; a dynamic run the
!> series /continuum/{time, displacement, velocity, stress, stress_zz, von_mises} and /continuum/energy/{time,
!> kinetic, strain, external_work, damping, balance, reaction_work} (h5py: one row per stored
!> state) with /continuum/energy/reaction (2: the x and y resultants of the reactions on the
!> prescribed dofs, N) per record.
!>
!> The XDMF file next to the results file (driver_results_xdmf) describes the mesh and its
!> fields from what this writer stored, by reference into the HDF5 file.
module driver_results_continuum
    use core_kinds, only: wp
    use core_constants, only: two_pi
    use core_error, only: error_t, make_error
    use io_hdf5_file, only: h5_file_t
    use fem_mesh2d, only: mesh2d_t
    use fem_continuum_model, only: continuum_model_t
    use fem_element_registry, only: element_slot_t, element_family
    implicit none
    private
    public :: continuum_writer_t

    !> Writes the continuum's results into an open HDF5 file.
    type :: continuum_writer_t
        !> Number of nodes and elements.
        integer :: n_nodes = 0, n_elements = 0
        !> Number of stored states (dynamic) so far.
        integer :: n_out = 0
        !> XDMF topology of /continuum/mesh/topology: 'Triangle', 'Quadrilateral' or 'Mixed'.
        character(len=:), allocatable :: topology
        !> Number of values of the topology dataset.
        integer :: topology_size = 0
        !> Whether the dynamic run's file has the series stress_zz and von_mises: false for the
        !> file of an earlier build continued by a restart, to which they are not appended
        !> (driver_results_xdmf then leaves them out).
        logical :: stress_measures = .true.
    contains
        !> Write the mesh, the materials and the sets (every analysis).
        procedure :: begin => writer_begin
        !> Create the series of a run with a time loop (after `begin`).
        procedure :: begin_series => writer_begin_series
        !> Take up a dynamic run's results file again at a restart (nothing written).
        procedure :: resume => writer_resume
        !> Static solution.
        procedure :: write_static => writer_write_static
        !> Modes.
        procedure :: write_modal => writer_write_modal
        !> One stored state of a dynamic run.
        procedure :: store => writer_store
        !> One energy record.
        procedure :: store_energy => writer_store_energy
    end type continuum_writer_t

contains

    !> Mesh, materials and sets.
    subroutine writer_begin(self, file, model, error)
        !> The writer.
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> The continuum (its mesh and materials).
        type(continuum_model_t), intent(in) :: model
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: topo(:)
        integer :: k, n
        self%n_nodes = model%mesh%node_count()
        self%n_elements = model%mesh%element_count()
        self%n_out = 0
        self%stress_measures = .true.
        call file%create_group('/continuum', error)
        if (allocated(error)) return
        call file%create_group('/continuum/mesh', error)
        if (allocated(error)) return
        call file%write_dataset('/continuum/mesh/coordinates', model%mesh%x, error)
        if (allocated(error)) return
        call file%write_attribute('/continuum/mesh/coordinates', 'units', 'm', error)
        if (allocated(error)) return
        call file%write_dataset('/continuum/mesh/connectivity', model%mesh%connectivity, error)
        if (allocated(error)) return
        call file%write_dataset('/continuum/mesh/kind', model%mesh%kind, error)
        if (allocated(error)) return
        call set_topology(self, model%mesh, topo)
        if (self%topology /= 'Mixed') then
            n = size(model%mesh%element_nodes(1))
            call file%write_dataset('/continuum/mesh/topology', reshape(topo, [n, self%n_elements]), error)
        else
            call file%write_dataset('/continuum/mesh/topology', topo, error)
        end if
        if (allocated(error)) return
        call write_materials(file, model, error)
        if (allocated(error)) return
        call file%create_group('/continuum/sets', error)
        if (.not. allocated(error)) call file%create_group('/continuum/sets/nodes', error)
        if (.not. allocated(error)) call file%create_group('/continuum/sets/elements', error)
        if (.not. allocated(error)) call file%create_group('/continuum/sets/edges', error)
        if (allocated(error)) return
        do k = 1, size(model%mesh%node_sets)
            call file%write_dataset('/continuum/sets/nodes/'//model%mesh%node_sets(k)%name, model%mesh%node_sets(k)%ids, error)
            if (allocated(error)) return
        end do
        do k = 1, size(model%mesh%element_sets)
            call file%write_dataset('/continuum/sets/elements/'//model%mesh%element_sets(k)%name, &
                                    model%mesh%element_sets(k)%ids, error)
            if (allocated(error)) return
        end do
        do k = 1, size(model%mesh%edge_sets)
            call file%write_dataset('/continuum/sets/edges/'//model%mesh%edge_sets(k)%name, model%mesh%edge_sets(k)%nodes, error)
            if (allocated(error)) return
        end do
    end subroutine writer_begin

    !> The series of a run with a time loop: time, displacement, velocity, stresses, energies.
    subroutine writer_begin_series(self, file, error)
        !> The writer (after `begin`).
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call series('/continuum/time', [integer ::], 's', error)
        if (.not. allocated(error)) call series('/continuum/displacement', [2, self%n_nodes], 'm', error)
        if (.not. allocated(error)) call series('/continuum/velocity', [2, self%n_nodes], 'm/s', error)
        if (.not. allocated(error)) call series('/continuum/stress', [3, self%n_elements], 'Pa', error)
        if (.not. allocated(error)) call series('/continuum/stress_zz', [self%n_elements], 'Pa', error)
        if (.not. allocated(error)) call series('/continuum/von_mises', [self%n_elements], 'Pa', error)
        if (.not. allocated(error)) call file%create_group('/continuum/energy', error)
        if (.not. allocated(error)) call series('/continuum/energy/time', [integer ::], 's', error)
        if (.not. allocated(error)) call series('/continuum/energy/kinetic', [integer ::], 'J', error)
        if (.not. allocated(error)) call series('/continuum/energy/strain', [integer ::], 'J', error)
        if (.not. allocated(error)) call series('/continuum/energy/external_work', [integer ::], 'J', error)
        if (.not. allocated(error)) call series('/continuum/energy/damping', [integer ::], 'J', error)
        if (.not. allocated(error)) call series('/continuum/energy/balance', [integer ::], 'J', error)
        if (.not. allocated(error)) call series('/continuum/energy/reaction_work', [integer ::], 'J', error)
        if (.not. allocated(error)) call series('/continuum/energy/reaction', [2], 'N', error)
    contains
        subroutine series(path, record_shape, units, error)
            character(len=*), intent(in) :: path, units
            integer, intent(in) :: record_shape(:)
            type(error_t), allocatable, intent(out) :: error
            call file%create_series(path, record_shape, error)
            if (allocated(error)) return
            call file%write_attribute(path, 'units', units, error)
        end subroutine series
    end subroutine writer_begin_series

    !> /continuum/mesh/material (each element's material) and /continuum/materials (the
    !> properties of each material, in the order of the deck's `material` records).
    subroutine write_materials(file, model, error)
        type(h5_file_t), intent(inout) :: file
        type(continuum_model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: values(:)
        integer, allocatable :: plane_strain(:)
        call file%write_dataset('/continuum/mesh/material', model%element_material, error)
        if (.not. allocated(error)) call file%create_group('/continuum/materials', error)
        if (allocated(error)) return
        ! (the components copied into an array first: passed directly they would be copied at
        ! the call, a temporary that -fcheck=all reports)
        values = model%materials%young
        call real_set('young', values, 'Pa', error)
        if (allocated(error)) return
        values = model%materials%poisson
        call real_set('poisson', values, '', error)
        if (allocated(error)) return
        values = model%materials%density
        call real_set('density', values, 'kg/m^3', error)
        if (allocated(error)) return
        values = model%materials%thickness
        call real_set('thickness', values, 'm', error)
        if (allocated(error)) return
        plane_strain = merge(1, 0, model%materials%plane_strain)
        call file%write_dataset('/continuum/materials/plane_strain', plane_strain, error)
    contains
        subroutine real_set(name, values, units, error)
            character(len=*), intent(in) :: name, units
            real(wp), intent(in) :: values(:)
            type(error_t), allocatable, intent(out) :: error
            call file%write_dataset('/continuum/materials/'//name, values, error)
            if (allocated(error) .or. len(units) == 0) return
            call file%write_attribute('/continuum/materials/'//name, 'units', units, error)
        end subroutine real_set
    end subroutine write_materials

    !> The XDMF topology of a mesh: its name and the 0-based connectivity, flat (one kind of
    !> element: the kind's topology, n nodes per element, element after element; mixed: each
    !> element's XDMF type code (4 triangle, 5 quadrilateral), then its nodes).
    subroutine set_topology(self, mesh, topo)
        type(continuum_writer_t), intent(inout) :: self
        type(mesh2d_t), intent(in) :: mesh
        integer, allocatable, intent(out) :: topo(:)
        type(element_slot_t), allocatable :: family(:)
        integer :: e, n
        call element_family(family)
        if (all(mesh%kind == mesh%kind(1))) then
            associate (el => family(mesh%kind(1))%element)
                n = el%node_count()
                self%topology = el%xdmf_topology()
            end associate
            topo = reshape(mesh%connectivity(1:n, :) - 1, [n*size(mesh%kind)])
        else
            self%topology = 'Mixed'
            allocate (topo(0))
            do e = 1, size(mesh%kind)
                associate (el => family(mesh%kind(e))%element)
                    n = el%node_count()
                    topo = [topo, el%xdmf_code(), mesh%connectivity(1:n, e) - 1]
                end associate
            end do
        end if
        self%topology_size = size(topo)
    end subroutine set_topology

    !> Take up the results file of a dynamic run at a restart, its series already cut to the
    !> checkpoint (driver_checkpoint::load_results): the count of stored states is that of
    !> /continuum/time. The series stress_zz and von_mises are appended to when the file has them.
    subroutine writer_resume(self, file, mesh, error)
        !> The writer.
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> The mesh (built from the deck).
        type(mesh2d_t), intent(in) :: mesh
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: topo(:), dims(:)
        self%n_nodes = mesh%node_count()
        self%n_elements = mesh%element_count()
        call set_topology(self, mesh, topo)
        call file%dataset_shape('/continuum/time', dims, error)
        if (allocated(error)) return
        self%n_out = dims(1)
        self%stress_measures = file%exists('/continuum/stress_zz') .and. file%exists('/continuum/von_mises')
    end subroutine writer_resume

    !> Static displacements (2, n_nodes), centre stresses (3, n_elements), their sigma_zz and
    !> von Mises stress (n_elements), reactions (2, n_nodes) and strain energy.
    subroutine writer_write_static(self, file, d, stress, sigma_zz, von_mises, reactions, strain_energy, error)
        !> The writer.
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> Displacements [m].
        real(wp), intent(in) :: d(:, :)
        !> Stresses [Pa].
        real(wp), intent(in) :: stress(:, :)
        !> sigma_zz of the stresses [Pa] (continuum_model_t%stress_measures).
        real(wp), intent(in) :: sigma_zz(:)
        !> Von Mises stress of the stresses [Pa].
        real(wp), intent(in) :: von_mises(:)
        !> Reactions of the supports on the prescribed dofs, 0 on the free ones [N].
        real(wp), intent(in) :: reactions(:, :)
        !> Strain energy [J].
        real(wp), intent(in) :: strain_energy
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call check_shapes(self, d, stress, sigma_zz, von_mises, error)
        if (allocated(error)) return
        if (any(shape(reactions) /= shape(d))) then
            call make_error(error, 'results: continuum reactions do not match the mesh')
            return
        end if
        call file%create_group('/continuum/static', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/static/displacement', d, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/static/displacement', 'units', 'm', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/static/stress', stress, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/static/stress', 'units', 'Pa', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/static/stress_zz', sigma_zz, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/static/stress_zz', 'units', 'Pa', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/static/von_mises', von_mises, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/static/von_mises', 'units', 'Pa', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/static/reactions', reactions, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/static/reactions', 'units', 'N', error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/static', 'strain_energy', strain_energy, error)
    end subroutine writer_write_static

    !> Circular frequencies, frequencies and mode shapes (2, n_nodes, n_modes).
    subroutine writer_write_modal(self, file, omega, shapes, error)
        !> The writer.
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> Circular frequencies [rad/s].
        real(wp), intent(in) :: omega(:)
        !> Mode shapes (2, n_nodes, n_modes), mass-normalised.
        real(wp), intent(in) :: shapes(:, :, :)
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group('/continuum/modal', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/modal/omega', omega, error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/modal/frequency', omega/two_pi, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/modal/omega', 'units', 'rad/s', error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/modal/frequency', 'units', 'Hz', error)
        if (.not. allocated(error)) call file%write_dataset('/continuum/modal/shapes', shapes, error)
        if (.not. allocated(error)) call file%write_attribute('/continuum/modal/shapes', 'units', &
                                                              'kg^-1/2 (mass-normalised)', error)
    end subroutine writer_write_modal

    !> Append one state: time, displacements, velocities (2, n_nodes), stresses (3, n_elements),
    !> their sigma_zz and von Mises stress (n_elements).
    subroutine writer_store(self, file, t, d, v, stress, sigma_zz, von_mises, error)
        !> The writer.
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> Time [s].
        real(wp), intent(in) :: t
        !> Displacements and velocities.
        real(wp), intent(in) :: d(:, :), v(:, :)
        !> Stresses [Pa].
        real(wp), intent(in) :: stress(:, :)
        !> sigma_zz of the stresses [Pa] (continuum_model_t%stress_measures).
        real(wp), intent(in) :: sigma_zz(:)
        !> Von Mises stress of the stresses [Pa].
        real(wp), intent(in) :: von_mises(:)
        !> Set on a size mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        call check_shapes(self, d, stress, sigma_zz, von_mises, error)
        if (allocated(error)) return
        call file%append('/continuum/time', t, error)
        if (.not. allocated(error)) call file%append('/continuum/displacement', d, error)
        if (.not. allocated(error)) call file%append('/continuum/velocity', v, error)
        if (.not. allocated(error)) call file%append('/continuum/stress', stress, error)
        if (self%stress_measures) then
            if (.not. allocated(error)) call file%append('/continuum/stress_zz', sigma_zz, error)
            if (.not. allocated(error)) call file%append('/continuum/von_mises', von_mises, error)
        end if
        if (allocated(error)) return
        self%n_out = self%n_out + 1
    end subroutine writer_store

    !> Append one energy record [J]; balance = kinetic + strain + damping - external work -
    !> reaction work - initial (the reaction work and resultant are 0 when absent).
    subroutine writer_store_energy(self, file, t, kinetic, strain, external_work, damping, balance, error, &
                                   reaction_work, reaction)
        !> The writer.
        class(continuum_writer_t), intent(inout) :: self
        !> The open results file.
        type(h5_file_t), intent(inout) :: file
        !> Time [s].
        real(wp), intent(in) :: t
        !> Energies [J].
        real(wp), intent(in) :: kinetic, strain, external_work, damping, balance
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        !> Work of the reactions on the prescribed dofs since the start [J].
        real(wp), intent(in), optional :: reaction_work
        !> Resultant (x, y) of the reactions on the prescribed dofs [N].
        real(wp), intent(in), optional :: reaction(2)
        real(wp) :: w, r(2)
        w = 0.0_wp
        r = 0.0_wp
        if (present(reaction_work)) w = reaction_work
        if (present(reaction)) r = reaction
        if (self%n_nodes == 0) then
            call make_error(error, 'results: continuum energy before begin')
            return
        end if
        call file%append('/continuum/energy/time', t, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/kinetic', kinetic, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/strain', strain, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/external_work', external_work, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/damping', damping, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/balance', balance, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/reaction_work', w, error)
        if (.not. allocated(error)) call file%append('/continuum/energy/reaction', r, error)
    end subroutine writer_store_energy

    !> Error unless d is (2, n_nodes), stress (3, n_elements), sigma_zz and von_mises (n_elements).
    subroutine check_shapes(self, d, stress, sigma_zz, von_mises, error)
        type(continuum_writer_t), intent(in) :: self
        real(wp), intent(in) :: d(:, :), stress(:, :), sigma_zz(:), von_mises(:)
        type(error_t), allocatable, intent(out) :: error
        if (size(d, 1) /= 2 .or. size(d, 2) /= self%n_nodes .or. size(stress, 1) /= 3 .or. &
            size(stress, 2) /= self%n_elements .or. size(sigma_zz) /= self%n_elements .or. &
            size(von_mises) /= self%n_elements) &
            call make_error(error, 'results: continuum fields do not match the mesh (begin first)')
    end subroutine check_shapes
end module driver_results_continuum
