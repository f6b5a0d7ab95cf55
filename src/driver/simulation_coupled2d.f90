!> Coupled continuum-disk runs: a deck with [continuum], [particles] and [coupling] (regions).
!>
!> The continuum part of the deck (mesh, materials, supports, loads, initial velocity, [time])
!> is read by the continuum run's own `init` (driver_simulation_continuum) on the deck without
!> the particle sections, and the particle part by the particle run's `init`
!> (driver_simulation_dem) on the deck without [continuum]; every error keeps its file, line and
!> keyword. [coupling] is read by driver_config_coupling2d, and coupling_arlequin2d builds the
!> coupled system, whose time step (coupling_coupled_step's arlequin_step) is the beam's.
!>
!> Results: /continuum (mesh, sets, displacement, velocity, centre stresses, and the FE side's
!> energies: kinetic and strain weighted by alpha), /dem and /coupling as in beam-coupled runs,
!> and `<deck>.xdmf` next to the HDF5 file with the mesh's fields and the disks (points with
!> their radius, grid "disks") per stored state. Checkpoints hold what a beam-particle coupled
!> run's hold (driver_checkpoint::save_coupled: the Newmark state of the continuum, the disks,
!> contacts and bonds, the multipliers and the constraint state) under the kind 'coupled2d';
!> at a restart the continuum writer reads its stored times back from the results file.
module driver_simulation_coupled2d
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str
    use core_signals, only: caught_signal, signal_name
    use io_deck, only: deck_t, deck_entry_t
    use io_paths, only: basename
    use io_progress, only: progress_t
    use fem_continuum_dynamics, only: continuum_dynamics_t
    use coupling_coupled_step, only: coupled_system_t, coupled_energies_t, arlequin_step, coupled_energies
    use coupling_arlequin2d, only: build_coupled2d
    use driver_config_coupling2d, only: coupled2d_setup_t, build_coupling2d_config
    use driver_results, only: results_writer_t
    use driver_results_continuum, only: continuum_writer_t
    use driver_results_dem, only: dem_writer_t
    use driver_results_coupled, only: coupled_writer_t
    use driver_run_dem, only: max_warnings, speed_warning, last_unconverged_warning
    use driver_guards, only: check_disks_state, step_start_t, take_step_start, check_tunnelling
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint, only: checkpoint_run_t, end_of_step, loop_state_t, checkpoint_create, checkpoint_commit, &
                                 checkpoint_discard, save_coupled, load_coupled, save_results, load_results, &
                                 save_dem_writer, load_dem_writer, save_coupled_writer, load_coupled_writer
    use driver_simulation, only: simulation_t, report_iface
    use driver_simulation_continuum, only: continuum_simulation_t
    use driver_simulation_dem, only: dem_simulation_t
    implicit none
    private
    public :: coupled2d_simulation_t, write_disks_xdmf

    !> A 2D continuum and particles glued in overlap regions.
    type, extends(simulation_t) :: coupled2d_simulation_t
        !> The continuum part (model, run settings, initial state).
        type(continuum_simulation_t) :: continuum
        !> The particle part (disks, walls, contact laws, solver).
        type(dem_simulation_t) :: particles
        !> The coupling from the deck.
        type(coupled2d_setup_t) :: coupling
        !> The coupled system.
        type(coupled_system_t), allocatable :: sys
    contains
        !> See `simulation_t%init`.
        procedure :: init => coupled2d_init
        !> See `simulation_t%describe`.
        procedure :: describe => coupled2d_describe
        !> See `simulation_t%run`.
        procedure :: run => coupled2d_run
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => coupled2d_checkpoint_kind
    end type coupled2d_simulation_t

contains

    !> Both models and the coupled system (library errors are attached to the first region line).
    subroutine coupled2d_init(self, deck, report, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        type(deck_t) :: part
        character(len=:), allocatable :: message
        integer :: i
        if (deck%get_word('run', 'analysis') /= 'dynamic') then
            call make_input_error(error, deck%file, deck%line('run', 'analysis'), 'analysis', &
                                  'a coupled run (continuum, particles and [coupling]) is a time integration: '// &
                                  'set analysis = dynamic')
            return
        end if
        ! The continuum without particles, coupling and gravity (weighted by the coupling).
        part = without(deck, [character(len=24) :: 'particles', 'walls', 'contacts', 'solver', 'coupling', &
                              'time theta', 'output contacts', 'continuum gravity'])
        call self%continuum%init(part, report, error)
        if (allocated(error)) return
        self%settings = self%continuum%settings
        ! The particles without the continuum, the coupling and the FE time scheme.
        part = without(deck, [character(len=24) :: 'continuum', 'coupling', 'time scheme', 'time beta', &
                              'time gamma'])
        call self%particles%init(part, report, error)
        if (allocated(error)) return
        call build_coupling2d_config(deck, self%settings, self%particles%dem%system%particles%gravity, &
                                     self%coupling, error)
        if (allocated(error)) return
        do i = 1, size(self%coupling%warnings)
            call report(self%coupling%warnings(i)%s)
        end do
        allocate (self%sys)
        call build_coupled2d(self%coupling%config, self%continuum%model, self%particles%dem%system, self%sys, error, &
                             beta=self%settings%beta, gamma=self%settings%gamma, u0=self%continuum%integ%u, &
                             v0=self%continuum%integ%v)
        if (allocated(error)) then
            message = error%message
            call make_input_error(error, deck%file, self%coupling%region_line, 'region', message)
        end if
    end subroutine coupled2d_init

    !> The deck without the entries of the given sections or 'section keyword' pairs.
    function without(deck, names) result(part)
        type(deck_t), intent(in) :: deck
        character(len=*), intent(in) :: names(:)
        type(deck_t) :: part
        logical, allocatable :: keep(:)
        integer :: i
        allocate (keep(size(deck%entries)))
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                keep(i) = .not. (any(names == e%section) .or. any(names == e%section//' '//e%keyword))
            end associate
        end do
        part = deck
        part%entries = pack(deck%entries, keep)
    end function without

    !> 'coupled dynamic analysis of a continuum, 32 elements, 64 disks, 64 coupled'.
    function coupled2d_describe(self) result(text)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = 'coupled '//self%settings%analysis//' analysis of a continuum, '// &
               to_str(self%continuum%model%mesh%element_count())//' elements, '// &
               to_str(self%sys%dem%particles%n)//' disks, '//to_str(self%sys%op%n_points)//' coupled'
    end function coupled2d_describe

    !> The coupled time integration; results into `out` and the XDMF file next to it.
    subroutine coupled2d_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(coupled2d_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines.
        logical, intent(in) :: quiet
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> Checkpoints (and the one to restart from).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        type(continuum_writer_t) :: fe_out
        type(dem_writer_t) :: dem_out
        type(coupled_writer_t) :: cpl_out
        type(progress_t) :: progress
        type(step_start_t) :: start
        character(len=:), allocatable :: xdmf
        character(len=512) :: buf
        integer(i8) :: n_steps, k, k0
        integer :: unconverged
        logical :: speed_warned, stop
        associate (sys => self%sys, model => self%continuum%model, run => self%settings)
            n_steps = run%n_steps
            unconverged = 0
            speed_warned = .false.
            k0 = 0
            if (ck%restart) then
                call restore(error)
                if (allocated(error)) return
            else
                call fe_out%begin(out%file, model%mesh, 'dynamic', error)
                if (allocated(error)) return
                call dem_out%begin(out%file, sys%dem, self%particles%dem%material_id, &
                                   self%particles%dem%store_contacts, error)
                if (allocated(error)) return
                call cpl_out%begin(out%file, sys, error)
                if (allocated(error)) return
                if (size(sys%mediator_nodes) > 0) call out%file%write_dataset('/coupling/mediator_nodes', &
                                                                              sys%mediator_nodes, error)
                if (allocated(error)) return
                k = 0
                call audit_step(.true.)
                call store(error)
                if (allocated(error)) return
            end if
            call progress%start(n_steps, run%t_end, run%progress_seconds)
            call ck%schedule%start()
            do k = k0 + 1, n_steps
                call take_step_start(start, sys%dem%particles, sys%dem%walls)
                call arlequin_step(sys, error)
                if (allocated(error)) return
                call audit_step(.false.)
                call check_step(error)
                if (allocated(error)) return
                call dem_out%record_step(out%file, sys%dem%stats, error)
                if (allocated(error)) return
                call cpl_out%record_step(out%file, sys, error)
                if (allocated(error)) return
                if (.not. sys%stats%converged) call warn_unconverged()
                if (.not. speed_warned) call check_speed()
                call end_of_step(k, n_steps, run%output_interval, ck%schedule, store, checkpoint, stop, error)
                if (allocated(error)) return
                if (stop) then
                    ! Stop request: the step just done is the last output.
                    call out%stop_at(signal_name(caught_signal()), k, sys%fe%t)
                    n_steps = k
                    exit
                end if
                if (.not. quiet .and. progress%due()) call report(progress%line(k, sys%fe%t))
            end do
            call dem_out%finish(out%file, sys%dem, unconverged, error)
            if (allocated(error)) return
            call cpl_out%finish(out%file, error)
            if (allocated(error)) return
            call summary()
            call out%write_summary(int(n_steps), progress%elapsed(), error)
            if (allocated(error)) return
            if (out%stopped()) return
            xdmf = out%final_path(1:len(out%final_path) - 3)//'.xdmf'
            call fe_out%write_xdmf(xdmf, basename(out%final_path), error)
            if (allocated(error)) return
            call write_disks_xdmf(xdmf, basename(out%final_path), sys%dem%particles%n, fe_out%times, error)
        end associate

    contains

        !> Restart: state, writer counters and results file from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            real(wp), allocatable :: totals(:)
            call dem_out%resume(self%sys%dem, self%particles%dem%store_contacts)
            call cpl_out%resume(self%sys)
            call load_coupled(ck%source, self%sys, error)
            ! The continuum's audit (its accumulated works; the rest follows from the state), the
            ! multipliers' work through the prescribed dofs and C_p u_p at the restart time.
            if (.not. allocated(error)) call ck%source%read_attribute('/coupling', 'continuum_audit', totals, error)
            if (.not. allocated(error)) then
                call audit_step(.true., totals(1:4))
                self%sys%prescribed_coupling_work = totals(5)
                self%sys%cp = 0.0_wp
                call self%sys%op%add_prescribed(self%sys%fe%t, 0, self%sys%cp)
            end if
            if (.not. allocated(error)) call load_dem_writer(ck%source, dem_out, error)
            if (.not. allocated(error)) call load_coupled_writer(ck%source, cpl_out, error)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            call fe_out%resume(out%file, self%continuum%model%mesh, error)
            if (allocated(error)) return
            k0 = ck%start%step
            unconverged = ck%start%unconverged
            speed_warned = ck%start%speed_warned
        end subroutine restore

        !> Write a checkpoint after step k (the buffered per-step values are written first).
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call dem_out%flush_buffer(out%file, error)
            if (.not. allocated(error)) call cpl_out%flush_buffer(out%file, error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, self%checkpoint_kind(), &
                                   loop_state_t(k, unconverged, speed_warned, .false.), self%sys%fe%t, &
                                   out%run_id, error)
            if (.not. allocated(error)) call save_coupled(f, self%sys, error)
            if (.not. allocated(error)) call f%write_attribute('/coupling', 'continuum_audit', &
                                                               [self%continuum%audit%totals(), &
                                                                self%sys%prescribed_coupling_work], error)
            if (.not. allocated(error)) call save_dem_writer(f, dem_out, error)
            if (.not. allocated(error)) call save_coupled_writer(f, cpl_out, error)
            if (.not. allocated(error)) call save_results(f, out, error)
            if (allocated(error)) then
                call checkpoint_discard(f, ck%path)
                return
            end if
            call checkpoint_commit(f, ck%path, error)
            if (allocated(error)) return
            ck%last_step = k
            ck%last_time = self%sys%fe%t
        end subroutine checkpoint

        !> One stored output of the three parts.
        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: u(:), v(:), stress(:, :)
            type(coupled_energies_t) :: en
            integer :: n
            associate (sys => self%sys, model => self%continuum%model)
                u = model%expand(sys%fe%u, sys%fe%t)
                v = model%expand(sys%fe%v, sys%fe%t, 1)
                n = model%mesh%node_count()
                call model%centre_stresses(u, stress, error)
                if (allocated(error)) return
                en = coupled_energies(sys)
                if (.not. (all(ieee_is_finite(stress)) .and. ieee_is_finite(en%balance))) then
                    write (buf, '(a,es13.5e3,a)') 'coupled continuum: a stress or an energy is not finite at t = ', &
                        sys%fe%t, ' s; likely cause: a time step far too large, or loads or moduli far out of scale'
                    call make_error(error, trim(buf))
                    return
                end if
                call fe_out%store(out%file, sys%fe%t, reshape(u, [2, n]), reshape(v, [2, n]), stress, error)
                if (allocated(error)) return
                associate (au => self%continuum%audit)
                    call fe_out%store_energy(out%file, sys%fe%t, au%kinetic, au%strain, au%load_work, au%damping, &
                                             au%balance(), error, au%reaction_work, au%reaction_resultant)
                end associate
                if (allocated(error)) return
                call dem_out%store(out%file, sys%dem, error)
                if (allocated(error)) return
                call cpl_out%store(out%file, sys, error)
                if (allocated(error)) return
            end associate
            call out%flush(error)
        end subroutine store

        !> The continuum's audit of the whole body (prescribed dofs and reactions included) on
        !> the weighted operator: started (resumed with the totals of a checkpoint), or advanced
        !> by the step just made.
        subroutine audit_step(first, totals)
            logical, intent(in) :: first
            real(wp), intent(in), optional :: totals(4)
            select type (ops => self%sys%model)
            type is (continuum_dynamics_t)
                if (first .and. present(totals)) then
                    call self%continuum%audit%resume(ops, self%continuum%model, self%sys%fe, totals)
                else if (first) then
                    call self%continuum%audit%start(ops, self%continuum%model, self%sys%fe)
                else
                    call self%continuum%audit%advance(ops, self%continuum%model, self%sys%fe)
                end if
            end select
        end subroutine audit_step

        !> Guards after a step: finite continuum and disk states, disks in the box, no tunnelling.
        subroutine check_step(error)
            type(error_t), allocatable, intent(out) :: error
            associate (sys => self%sys)
                ! State and energy accounts (a checkpoint may follow: it must hold finite values).
                if (.not. (all(ieee_is_finite(sys%fe%u)) .and. all(ieee_is_finite(sys%fe%v)) .and. &
                           all(ieee_is_finite([sys%fe%kinetic, sys%fe%strain, sys%fe%external_work, &
                                               sys%fe%damping_dissipation, sys%fe%coupling_work])))) then
                    write (buf, '(a,i0,a,es13.5e3,a)') 'coupled continuum: the state is not finite after step ', k, &
                        ' (t = ', sys%fe%t, ' s); likely cause: loads or moduli far out of scale'
                    call make_error(error, trim(buf))
                    return
                end if
                call check_disks_state(k, sys%fe%t, sys%dem%particles, sys%dem%energies, error)
                if (allocated(error)) return
                call check_tunnelling(k, sys%fe%t, self%settings%h, sys%dem%scheme%alert, start, sys%dem%particles, &
                                      sys%dem%walls, sys%dem%contacts, error)
            end associate
        end subroutine check_step

        !> Warning for an unconverged step (the first max_warnings ones).
        subroutine warn_unconverged()
            unconverged = unconverged + 1
            if (unconverged > max_warnings) return
            write (buf, '(a,i0,a,es12.4e3,a,i0,a)') 'warning: step ', k, ' (t = ', self%sys%fe%t, &
                ' s): the joint contact/multiplier solve did not converge in ', self%sys%stats%sweeps, &
                ' sweeps; the constraint still holds'
            call report(trim(buf))
            if (unconverged == max_warnings) call report(last_unconverged_warning())
        end subroutine warn_unconverged

        !> Warning (once) when a disk moved farther than the alert distance in the step.
        subroutine check_speed()
            character(len=:), allocatable :: line
            line = speed_warning(self%sys%dem%particles, self%settings%h, self%sys%dem%scheme%alert, self%sys%fe%t)
            if (len(line) == 0) return
            speed_warned = .true.
            call report(line)
        end subroutine check_speed

        !> Closing lines: model, residuals, energy balance, times.
        subroutine summary()
            type(coupled_energies_t) :: en
            associate (sys => self%sys)
                en = coupled_energies(sys)
                write (buf, '(a,i0,a,i0,a,i0,a,i0,a,es13.5e3,a)') 'coupled run: ', &
                    self%continuum%model%mesh%element_count(), ' elements, ', sys%dem%particles%n, ' disks (', &
                    sys%op%n_points, ' coupled), ', n_steps, ' steps to t = ', sys%fe%t, ' s'
                call report(trim(buf))
                write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'constraint: max |Pi (q - C u)| = ', &
                    cpl_out%max_position, ' m (per disk, from the coordinates ', cpl_out%max_coordinate, &
                    ' m), max velocity residual ', cpl_out%max_velocity, ' m/s'
                call report(trim(buf))
                call report('unconverged steps: '//to_str(unconverged)//' of '//to_str(n_steps))
                write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'energy balance residual ', en%balance, &
                    ' J (max over the outputs ', cpl_out%max_balance, ' J; external work ', &
                    en%fe_external_work + en%dem_external_work + en%dem_drive_work, ' J)'
                call report(trim(buf))
                call report(progress%summary_line(n_steps, sys%fe%t))
            end associate
        end subroutine summary
    end subroutine coupled2d_run

    !> Add the disks to an XDMF file written by continuum_writer_t%write_xdmf: a temporal
    !> collection "disks" of Polyvertex grids, the centres from /dem/position (x, y of each
    !> stored state), with the radius and the velocity as point attributes (ParaView: Glyph,
    !> sphere or 2D disk scaled by "radius", scale factor 2 for the diameter).
    subroutine write_disks_xdmf(path, h5_name, n, times, error)
        !> The XDMF file (rewritten with the disks before its closing tags).
        character(len=*), intent(in) :: path
        !> Name of the HDF5 file next to it.
        character(len=*), intent(in) :: h5_name
        !> Number of disks.
        integer, intent(in) :: n
        !> Stored times (one per state of /dem/position).
        real(wp), intent(in) :: times(:)
        !> Set when the file cannot be read or written.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text, tail
        character(len=4096) :: line
        character(len=32) :: tb
        integer :: unit, ios, k, cut
        open (newunit=unit, file=path, status='old', action='read', iostat=ios)
        if (ios /= 0) then
            call make_error(error, 'cannot read '//path)
            return
        end if
        text = ''
        do
            read (unit, '(a)', iostat=ios) line
            if (ios /= 0) exit
            text = text//trim(line)//new_line('a')
        end do
        close (unit)
        cut = index(text, ' </Domain>')
        if (cut == 0) then
            call make_error(error, path//': no </Domain> to add the disks before')
            return
        end if
        tail = text(cut:)
        text = text(1:cut - 1)
        text = text//'  <Grid Name="disks" GridType="Collection" CollectionType="Temporal">'//new_line('a')
        do k = 1, size(times)
            write (tb, '(es24.16e3)') times(k)
            text = text//'   <Grid Name="disks_'//to_str(k - 1)//'" GridType="Uniform">'//new_line('a')// &
                   '    <Time Value="'//trim(adjustl(tb))//'"/>'//new_line('a')// &
                   '    <Topology TopologyType="Polyvertex" NumberOfElements="'//to_str(n)//'"/>'//new_line('a')// &
                   '    <Geometry GeometryType="XY">'//new_line('a')// &
                   slab('/dem/position')// &
                   '    </Geometry>'//new_line('a')// &
                   '    <Attribute Name="radius" AttributeType="Scalar" Center="Node">'//new_line('a')// &
                   '     <DataItem Dimensions="'//to_str(n)//'" NumberType="Float" Precision="8" Format="HDF">'// &
                   h5_name//':/dem/particles/radius</DataItem>'//new_line('a')// &
                   '    </Attribute>'//new_line('a')// &
                   '    <Attribute Name="velocity" AttributeType="Vector" Center="Node">'//new_line('a')// &
                   slab('/dem/velocity')// &
                   '    </Attribute>'//new_line('a')// &
                   '   </Grid>'//new_line('a')
        end do
        text = text//'  </Grid>'//new_line('a')//tail
        open (newunit=unit, file=path, status='replace', action='write', iostat=ios)
        if (ios /= 0) then
            call make_error(error, 'cannot write '//path)
            return
        end if
        write (unit, '(a)', advance='no') text
        close (unit)
    contains
        !> x, y of state k of a (records, n, 3) series.
        function slab(dataset) result(s)
            character(len=*), intent(in) :: dataset
            character(len=:), allocatable :: s
            s = '     <DataItem ItemType="HyperSlab" Dimensions="'//to_str(n)//' 2" Type="HyperSlab">'//new_line('a')// &
                '      <DataItem Dimensions="3 3" Format="XML">'//to_str(k - 1)//' 0 0 1 1 1 1 '//to_str(n)// &
                ' 2</DataItem>'//new_line('a')// &
                '      <DataItem Dimensions="'//to_str(size(times))//' '//to_str(n)//' 3" NumberType="Float" '// &
                'Precision="8" Format="HDF">'//h5_name//':'//dataset//'</DataItem>'//new_line('a')// &
                '     </DataItem>'//new_line('a')
        end function slab
    end subroutine write_disks_xdmf

    !> 'coupled2d'.
    function coupled2d_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(coupled2d_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'coupled2d'
    end function coupled2d_checkpoint_kind
end module driver_simulation_coupled2d
