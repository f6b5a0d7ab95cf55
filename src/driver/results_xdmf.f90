!> `<deck>.xdmf` next to the results file: what the HDF5 file holds, described by reference
!> (io_xdmf: whole datasets and hyperslabs, no data copied) for ParaView's "XDMF Reader".
!>
!> The description is read from the results file itself (its root attribute `analysis`, the
!> groups it has and the shapes of their datasets), so that it is the same for every kind of
!> run and after a restart (doc/output.md, "XDMF file"). This module assembles it: the
!> analysis gives the series of stored states (driver_xdmf_series: one grid per part when
!> static, a temporal collection per part over the modes or the stored times otherwise), and
!> every registered part (driver_xdmf_part) of that analysis that finds itself in the file
!> writes its grids: the beam (driver_xdmf_beam), the 2D continuum (driver_xdmf_continuum),
!> the disks and walls (driver_xdmf_dem). ParaView shows several parts as the blocks of one
!> data set, named after the parts at every time (a spatial collection per time would name
!> them "beam[k]" with the state k, which changes with the time and breaks a block selection).
!> A new model kind adds its part types and one line each in `registered_parts`.
module driver_results_xdmf
    use core_error, only: error_t
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t
    use driver_xdmf_series, only: xdmf_series_t, new_series
    use driver_xdmf_part, only: xdmf_part_t, xdmf_part_slot_t
    use driver_xdmf_beam, only: beam_static_xdmf_t, beam_modal_xdmf_t, beam_dynamic_xdmf_t
    use driver_xdmf_continuum, only: continuum_static_xdmf_t, continuum_modal_xdmf_t, continuum_dynamic_xdmf_t
    use driver_xdmf_dem, only: disks_xdmf_t, walls_xdmf_t
    implicit none
    private
    public :: write_results_xdmf

contains

    !> Write the XDMF file `path` describing the open results file `file`.
    !>
    !> The results file is read first, whole (`survey`); what follows writes the XDMF file alone.
    subroutine write_results_xdmf(file, path, h5_name, error, results_read)
        !> The results file (open; every output written).
        type(h5_file_t), intent(in) :: file
        !> XDMF file to write.
        character(len=*), intent(in) :: path
        !> Name of the HDF5 file as seen from the XDMF file's folder (its final name).
        character(len=*), intent(in) :: h5_name
        !> Set on a read failure, an inconsistent file, or when the XDMF file cannot be written.
        type(error_t), allocatable, intent(out) :: error
        !> Whether the results file was read and found consistent: an error is then one of the
        !> XDMF file itself (it cannot be created or written: a full disk, a quota, a file size
        !> limit), which says nothing against the results file.
        logical, intent(out) :: results_read
        class(xdmf_series_t), allocatable :: series
        type(xdmf_part_slot_t), allocatable :: parts(:)
        type(xdmf_file_t) :: x
        integer :: i, k
        results_read = .false.
        call survey(file, series, parts, error)
        if (allocated(error)) return
        results_read = .true.
        call x%open(path, h5_name, error)
        if (allocated(error)) return
        do i = 1, size(parts)
            associate (part => parts(i)%part)
                call series%begin_part(x, part%name())
                do k = 1, series%n_states
                    call part%write_grid(x, series, k)
                end do
                call series%end_part(x)
            end associate
        end do
        call x%close(error)
    end subroutine write_results_xdmf

    !> The parts of the results file, in the order of `registered_parts`, and its stored
    !> states (modes); an error when a series has fewer records than the states.
    subroutine survey(file, series, parts, error)
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> The stored states.
        class(xdmf_series_t), allocatable, intent(out) :: series
        !> The parts found in the file.
        type(xdmf_part_slot_t), allocatable, intent(out) :: parts(:)
        !> Set on a read failure or an inconsistent file.
        type(error_t), allocatable, intent(out) :: error
        type(xdmf_part_slot_t), allocatable :: known(:)
        character(len=:), allocatable :: analysis, states
        logical :: found
        integer :: i
        call file%read_attribute('/', 'analysis', analysis, error)
        if (allocated(error)) return
        call new_series(analysis, series)
        known = registered_parts()
        allocate (parts(0))
        do i = 1, size(known)
            if (known(i)%part%analysis() /= series%analysis()) cycle
            call known(i)%part%survey(file, found, error)
            if (allocated(error)) return
            if (found) parts = [parts, known(i)]
        end do
        ! the states are counted by the first part that has a dataset of them
        states = ''
        do i = 1, size(parts)
            states = parts(i)%part%states_dataset()
            if (len(states) > 0) exit
        end do
        call series%survey(file, states, error)
        if (allocated(error)) return
        do i = 1, size(parts)
            call parts(i)%part%check_records(file, series%n_states, error)
            if (allocated(error)) return
        end do
    end subroutine survey

    !> Every kind of part, in the order of the XDMF file.
    function registered_parts() result(parts)
        !> One part of each kind, not surveyed.
        type(xdmf_part_slot_t), allocatable :: parts(:)
        allocate (parts(0))
        call add(beam_static_xdmf_t())
        call add(beam_modal_xdmf_t())
        call add(beam_dynamic_xdmf_t())
        call add(continuum_static_xdmf_t())
        call add(continuum_modal_xdmf_t())
        call add(continuum_dynamic_xdmf_t())
        call add(disks_xdmf_t())
        call add(walls_xdmf_t())
    contains
        !> Append `part`.
        subroutine add(part)
            !> A part of one kind.
            class(xdmf_part_t), intent(in) :: part
            parts = [parts, xdmf_part_slot_t()]
            allocate (parts(size(parts))%part, source=part)
        end subroutine add
    end function registered_parts
end module driver_results_xdmf
