!> The results side of a checkpoint (driver_checkpoint): the counters of the results writers
!> and the record count of every dataset of the results file, to which a restart cuts the
!> file back.
module driver_checkpoint_results
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, string_t, split_lines
    use io_paths, only: file_exists
    use io_hdf5_file, only: h5_file_t
    use driver_results, only: results_writer_t
    use driver_results_mark, only: results_mark_t
    use driver_results_dem, only: dem_writer_t
    use driver_results_coupled, only: coupled_writer_t
    use driver_checkpoint_values, only: read_int_attr_1d, read_finite_attribute, require_finite, require_range, &
                                        damaged
    implicit none
    private
    public :: save_results, load_results, save_dem_writer, load_dem_writer
    public :: save_coupled_writer, load_coupled_writer, checkpoint_results_mark

contains

    !> Write the results writer's counters and the record count of every dataset of the
    !> results file (flushed before).
    subroutine save_results(file, out, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The results writer (open).
        type(results_writer_t), intent(in) :: out
        !> Set on a read or write failure.
        type(error_t), allocatable, intent(out) :: error
        character(len=256), allocatable :: paths(:)
        integer, allocatable :: counts(:)
        character(len=:), allocatable :: joined
        integer :: k
        call out%file%list_datasets(paths, counts, error)
        if (allocated(error)) return
        call file%create_group('/results', error)
        if (allocated(error)) return
        call file%write_attribute('/results', 'writer', real([out%beam%n_nodes, merge(1, 0, out%beam%have_state), &
                                                              merge(1, 0, out%beam%have_energy)], wp), error)
        if (allocated(error)) return
        call file%write_attribute('/results', 'energy0', out%beam%energy0, error)
        if (allocated(error)) return
        joined = ''
        do k = 1, size(paths)
            joined = joined//trim(paths(k))//new_line('a')
        end do
        call file%write_attribute('/results', 'datasets', joined, error)
        if (allocated(error) .or. size(paths) == 0) return
        call file%write_dataset('/results/records', counts, error)
    end subroutine save_results

    !> Restore the results writer's counters, and bring its (open) results file back to the
    !> checkpoint: datasets written after it are deleted, series cut to their record counts.
    !> The first write to the results file of a restart: everything read before it (the state)
    !> and in it is checked first.
    subroutine load_results(file, out, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The results writer, its file open for writing.
        type(results_writer_t), intent(inout) :: out
        !> Set on a read or write failure, or when a dataset of the checkpoint is missing.
        type(error_t), allocatable, intent(out) :: error
        character(len=256), allocatable :: paths(:)
        integer, allocatable :: counts(:), saved(:), w(:)
        character(len=:), allocatable :: joined
        type(string_t), allocatable :: names(:)
        integer :: k, j, n_saved
        real(wp) :: energy0
        call read_int_attr_1d(file, '/results', 'writer', w, error)
        if (allocated(error)) return
        if (size(w) /= 3) then
            call damaged(error, '/results@writer: '//to_str(size(w))//' values, not 3')
            return
        end if
        ! nodes, state series written, energy series written
        call require_range(w(1:1), 0, huge(0), '/results@writer value 1 (nodes)', error)
        if (.not. allocated(error)) call require_range(w(2:3), 0, 1, '/results@writer (flags)', error, first=2)
        if (.not. allocated(error)) call file%read_attribute('/results', 'energy0', energy0, error)
        if (.not. allocated(error)) call require_finite([energy0], '/results@energy0', error)
        if (allocated(error)) return
        out%beam%n_nodes = w(1)
        out%beam%have_state = w(2) /= 0
        out%beam%have_energy = w(3) /= 0
        out%beam%energy0 = energy0
        call file%read_attribute('/results', 'datasets', joined, error)
        if (allocated(error)) return
        ! the results' own dataset paths, one per line: other bytes are damage (not quoted)
        if (any([(.not. (joined(k:k) == new_line('a') .or. (iachar(joined(k:k)) >= 32 .and. &
                                                            iachar(joined(k:k)) <= 126)), k=1, len(joined))])) then
            call make_error(error, "checkpoint: '/results@datasets' holds bytes that are not a dataset path: the "// &
                            'checkpoint is damaged')
            return
        end if
        call split_lines(joined, names)
        n_saved = size(names)
        allocate (saved(0))
        if (n_saved > 0) call file%read_dataset('/results/records', saved, error)
        if (allocated(error)) return
        if (size(saved) /= n_saved) then
            call make_error(error, 'checkpoint: '//to_str(size(saved))//' record counts for '// &
                            to_str(n_saved)//' datasets: the checkpoint is damaged')
            return
        end if
        call out%file%list_datasets(paths, counts, error)
        if (allocated(error)) return
        ! The results file holds at least the records of the checkpoint: a count beyond it
        ! (a damaged checkpoint) would extend the series instead of cutting it.
        do k = 1, size(paths)
            j = find(trim(paths(k)))
            if (j == 0) cycle
            if (saved(j) >= 0 .and. saved(j) <= counts(k)) cycle
            call make_error(error, "checkpoint: it counts "//to_str(saved(j))//" records of '"// &
                            trim(paths(k))//"', the results file '"//out%file%path//"' holds "// &
                            to_str(counts(k))//': the checkpoint is damaged or not of these results')
            return
        end do
        ! Every dataset of the checkpoint must be there.
        do k = 1, size(names)
            if (.not. any(paths == names(k)%s)) then
                call make_error(error, "checkpoint: the results file '"//out%file%path// &
                                "' has no dataset '"//names(k)%s//"'")
                return
            end if
        end do
        ! the outputs stored whole at the checkpoint: the fewest records of the outputs' time
        ! series (/dem/bonds/time lists rupture events, not outputs)
        out%outputs = huge(0)
        do k = 1, size(names)
            associate (name => names(k)%s)
                if (len(name) < 5 .or. name == '/dem/bonds/time') cycle
                if (name(len(name) - 4:) == '/time') out%outputs = min(out%outputs, saved(k))
            end associate
        end do
        if (out%outputs == huge(0)) out%outputs = 0
        call out%mark_running(error)
        if (allocated(error)) return
        ! Every dataset of the file: kept (series cut to the checkpoint) or deleted.
        do k = 1, size(paths)
            j = find(trim(paths(k)))
            if (j == 0) then
                call out%file%delete(trim(paths(k)), error)
            else if (counts(k) /= saved(j)) then
                call out%file%resize_series(trim(paths(k)), saved(j), error)
            end if
            if (allocated(error)) return
        end do
    contains
        !> Index of `path` in the checkpoint's list (0: not there).
        integer function find(path)
            character(len=*), intent(in) :: path
            do find = 1, size(names)
                if (names(find)%s == path) return
            end do
            find = 0
        end function find
    end subroutine load_results

    !> The results the checkpoint at `path` continues: its run id and the record count of every
    !> dataset of its results file. The run id is '' when there is no checkpoint there or it
    !> cannot be read; the lists are empty when it records no datasets or they cannot be read
    !> (a file then holds its results by its run id alone). The values are not checked: a
    !> restart checks them as it reads the checkpoint (`load_results`).
    function checkpoint_results_mark(path) result(mark)
        !> Path of the checkpoint.
        character(len=*), intent(in) :: path
        !> Its results' run id and record counts.
        type(results_mark_t) :: mark
        type(h5_file_t) :: file
        type(error_t), allocatable :: error, ignored
        character(len=:), allocatable :: joined
        integer, allocatable :: saved(:)
        mark%run_id = ''
        mark%paths = [string_t ::]
        mark%counts = [integer ::]
        if (.not. file_exists(path)) return
        call file%open(path, error)
        if (allocated(error)) return
        call file%read_attribute('/', 'run_id', joined, error)
        if (.not. allocated(error)) then
            mark%run_id = joined
            call file%read_attribute('/results', 'datasets', joined, error)
        end if
        if (.not. allocated(error)) then
            allocate (saved(0))
            if (index(joined, new_line('a')) > 0) call file%read_dataset('/results/records', saved, error)
        end if
        if (.not. allocated(error)) then
            call split_lines(joined, mark%paths)
            if (size(saved) == size(mark%paths)) then
                mark%counts = saved
            else
                mark%paths = [string_t ::]
            end if
        end if
        call file%close(ignored)
    end function checkpoint_results_mark

    !> Write the counters of the particle writer (its buffered statistics written before).
    subroutine save_dem_writer(file, writer, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The writer, nothing buffered.
        type(dem_writer_t), intent(in) :: writer
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group('/writers', error)
        if (allocated(error)) return
        call file%write_attribute('/writers', 'dem', real([writer%n_out, writer%n_contacts_stored, &
                                                           writer%n_steps, writer%n_buffered, writer%n_ruptures, &
                                                           writer%n_block_given_up, &
                                                           writer%n_block_given_up_unconverged, &
                                                           writer%n_block_given_up_reverted], wp), error)
    end subroutine save_dem_writer

    !> Read the counters of the particle writer (begun again: its buffers exist).
    subroutine load_dem_writer(file, writer, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The writer.
        type(dem_writer_t), intent(inout) :: writer
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: c(:)
        call read_int_attr_1d(file, '/writers', 'dem', c, error)
        if (allocated(error)) return
        if (size(c) /= 8) then
            call make_error(error, 'checkpoint: /writers: wrong number of particle writer counters')
            return
        end if
        call require_range(c, 0, huge(0), '/writers@dem', error)
        if (allocated(error)) return
        call require_range(c(6:6), 0, c(3), '/writers@dem value 6 (steps whose bonded block was given up, at most '// &
                           'the steps recorded)', error)
        if (allocated(error)) return
        call require_range(c(7:7), 0, c(6), '/writers@dem value 7 (steps whose bonded block was given up unconverged '// &
                           'at its cap, at most those given up)', error)
        if (allocated(error)) return
        call require_range(c(8:8), 0, c(3) - c(6), '/writers@dem value 8 (steps whose give-up at the cap was taken '// &
                           'back, at most the steps recorded not given up)', error)
        if (allocated(error)) return
        if (c(4) /= 0) then
            call make_error(error, 'checkpoint: the particle writer had unwritten statistics')
            return
        end if
        writer%n_out = c(1)
        writer%n_contacts_stored = c(2)
        writer%n_steps = c(3)
        writer%n_buffered = 0
        writer%n_ruptures = c(5)
        writer%n_block_given_up = c(6)
        writer%n_block_given_up_unconverged = c(7)
        writer%n_block_given_up_reverted = c(8)
    end subroutine load_dem_writer

    !> Write the counters and running maxima of the coupling writer (nothing buffered).
    subroutine save_coupled_writer(file, writer, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The writer, nothing buffered.
        type(coupled_writer_t), intent(in) :: writer
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group('/writers', error)
        if (allocated(error)) return
        call file%write_attribute('/writers', 'coupled', real([writer%n_out, writer%n_steps, &
                                                               writer%n_buffered], wp), error)
        if (allocated(error)) return
        call file%write_attribute('/writers', 'coupled_max', [writer%max_position, writer%max_velocity, &
                                                              writer%max_coordinate, writer%max_balance], error)
    end subroutine save_coupled_writer

    !> Read the counters and running maxima of the coupling writer (begun again).
    subroutine load_coupled_writer(file, writer, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The writer.
        type(coupled_writer_t), intent(inout) :: writer
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: c(:)
        real(wp), allocatable :: m(:)
        call read_int_attr_1d(file, '/writers', 'coupled', c, error)
        if (allocated(error)) return
        if (size(c) /= 3) then
            call make_error(error, 'checkpoint: /writers: wrong number of coupling writer counters')
            return
        end if
        call require_range(c, 0, huge(0), '/writers@coupled', error)
        if (.not. allocated(error)) call read_finite_attribute(file, '/writers', 'coupled_max', m, 4, error)
        if (allocated(error)) return
        if (c(3) /= 0) then
            call make_error(error, 'checkpoint: the coupling writer had unwritten statistics')
            return
        end if
        writer%n_out = c(1)
        writer%n_steps = c(2)
        writer%n_buffered = 0
        writer%max_position = m(1)
        writer%max_velocity = m(2)
        writer%max_coordinate = m(3)
        writer%max_balance = m(4)
    end subroutine load_coupled_writer
end module driver_checkpoint_results
