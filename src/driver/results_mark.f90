!> What a checkpoint records of the results file it continues (driver_checkpoint_results): the
!> run id (root attribute 'run_id') and the record count of every dataset at the checkpoint.
!> A file holds the checkpoint's results when it has that run id and at least those records:
!> a restart cuts it back to the checkpoint. A file of the same run with fewer records (the
!> finished file of an earlier end time, after a continuation went further; a copy of it) is
!> an earlier state of that run, from which the checkpoint cannot be continued.
!>
!> `results_file_damage` tells a damaged file (truncated, overwritten in part: HDF5 cannot
!> open it, read its run id or list its datasets) from one of another run, so that a restart
!> says which it is.
module driver_results_mark
    use core_error, only: error_t
    use core_strings, only: string_t
    use io_hdf5_file, only: h5_file_t
    use io_paths, only: file_exists
    implicit none
    private
    public :: results_mark_t, results_file_damage, results_deck_file, results_root_text

    !> The results of a checkpoint: run id, datasets and their record counts.
    type :: results_mark_t
        !> Root attribute 'run_id' of the results file ('': no checkpoint, no file holds it).
        character(len=:), allocatable :: run_id
        !> Absolute paths of the datasets of the results file at the checkpoint.
        type(string_t), allocatable :: paths(:)
        !> Record count (last dimension) of each dataset at the checkpoint.
        integer, allocatable :: counts(:)
    contains
        !> Whether a file holds the checkpoint's results (its run id, at least its records).
        procedure :: held_by => mark_held_by
    end type results_mark_t

contains

    !> Whether the HDF5 file `path` has the mark's run id and, for every dataset of the mark, at
    !> least its record count. False when there is no such file, it cannot be read, or the mark's
    !> run id is ''.
    logical function mark_held_by(self, path) result(held)
        !> The checkpoint's results.
        class(results_mark_t), intent(in) :: self
        !> Path of the file (need not exist).
        character(len=*), intent(in) :: path
        type(h5_file_t) :: f
        type(error_t), allocatable :: e
        character(len=:), allocatable :: value
        character(len=256), allocatable :: names(:)
        integer, allocatable :: records(:)
        integer :: k, j
        held = .false.
        if (.not. allocated(self%run_id)) return
        if (len(self%run_id) == 0 .or. .not. file_exists(path)) return
        call f%open(path, e)
        if (allocated(e)) return
        call f%read_attribute('/', 'run_id', value, e)
        if (.not. allocated(e)) held = value == self%run_id
        if (held .and. allocated(self%paths)) then
            call f%list_datasets(names, records, e)
            held = .not. allocated(e)
            do k = 1, size(self%paths)
                if (.not. held) exit
                held = .false.
                do j = 1, size(names)
                    if (trim(names(j)) /= self%paths(k)%s) cycle
                    held = records(j) >= self%counts(k)
                    exit
                end do
            end do
        end if
        call f%close(e)
    end function mark_held_by

    !> Why the existing HDF5 file `path` is damaged (HDF5's message), or '' when it opens and
    !> every dataset's shape reads (a file without run id is not called damaged: it may be
    !> another program's).
    function results_file_damage(path) result(reason)
        !> Path of the file.
        character(len=*), intent(in) :: path
        !> HDF5's message, or ''.
        character(len=:), allocatable :: reason
        type(h5_file_t) :: f
        type(error_t), allocatable :: e, ignored
        character(len=256), allocatable :: names(:)
        integer, allocatable :: records(:)
        reason = ''
        call f%open(path, e)
        if (allocated(e)) then
            reason = e%message
            return
        end if
        call f%list_datasets(names, records, e)
        if (allocated(e)) reason = e%message
        call f%close(ignored)
    end function results_file_damage

    !> The deck path a results file records (root attribute 'deck_file', as given on the
    !> command line of its run), or '' when the file or the attribute cannot be read.
    function results_deck_file(path) result(deck_file)
        !> Path of the results file.
        character(len=*), intent(in) :: path
        !> The deck's path, or ''.
        character(len=:), allocatable :: deck_file
        deck_file = results_root_text(path, 'deck_file')
    end function results_deck_file

    !> A text root attribute of a results file ('deck_file', 'deck_text', ...), or '' when the
    !> file or the attribute cannot be read.
    function results_root_text(path, name) result(text)
        !> Path of the results file.
        character(len=*), intent(in) :: path
        !> Name of the attribute.
        character(len=*), intent(in) :: name
        !> Its value, or ''.
        character(len=:), allocatable :: text
        type(h5_file_t) :: f
        type(error_t), allocatable :: e, ignored
        text = ''
        if (.not. file_exists(path)) return
        call f%open(path, e)
        if (allocated(e)) return
        call f%read_attribute('/', name, text, e)
        if (allocated(e)) text = ''
        call f%close(ignored)
    end function results_root_text
end module driver_results_mark
