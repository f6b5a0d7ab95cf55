!> The particles (/dem) in the XDMF file (driver_results_xdmf), stored states of a dynamic
!> analysis: the disks as a point grid "disks" (their centres) with radius, material,
!> velocity, rotation and angular velocity (ParaView: Glyph, 2D disk or sphere, scaled by
!> "radius", factor 2 for the diameter), and the walls as segments "walls" with their material.
module driver_xdmf_dem
    use core_error, only: error_t
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t, xdmf_whole, xdmf_slab
    use driver_xdmf_series, only: xdmf_series_t
    use driver_xdmf_part, only: xdmf_part_t, shape_of, require_records
    implicit none
    private
    public :: disks_xdmf_t, walls_xdmf_t

    !> A part of the particle system: dynamic, its times in /dem/time.
    type, abstract, extends(xdmf_part_t) :: dem_xdmf_t
    contains
        procedure :: analysis => dem_analysis
        procedure :: states_dataset => dem_states
    end type dem_xdmf_t

    !> The disks (/dem/position).
    type, extends(dem_xdmf_t) :: disks_xdmf_t
        !> Disks.
        integer :: n = 0
    contains
        procedure :: name => disks_name
        procedure :: survey => disks_survey
        procedure :: check_records => disks_records
        procedure :: write_grid => disks_grid
    end type disks_xdmf_t

    !> The walls (/dem/walls/position).
    type, extends(dem_xdmf_t) :: walls_xdmf_t
        !> Walls.
        integer :: n = 0
    contains
        procedure :: name => walls_name
        procedure :: survey => walls_survey
        procedure :: check_records => walls_records
        procedure :: write_grid => walls_grid
    end type walls_xdmf_t

contains

    !> 'dynamic'.
    function dem_analysis(self) result(name)
        !> The part.
        class(dem_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'dynamic'
    end function dem_analysis

    !> The particle system's stored times.
    function dem_states(self) result(path)
        !> The part.
        class(dem_xdmf_t), intent(in) :: self
        !> Dataset path.
        character(len=:), allocatable :: path
        path = '/dem/time'
    end function dem_states

    !> 'disks'.
    function disks_name(self) result(name)
        !> The part.
        class(disks_xdmf_t), intent(in) :: self
        !> Name of the part.
        character(len=:), allocatable :: name
        name = 'disks'
    end function disks_name

    !> Whether the results file has disks, and how many.
    subroutine disks_survey(self, file, found, error)
        !> The part.
        class(disks_xdmf_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Whether the file has disks.
        logical, intent(out) :: found
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:)
        found = file%exists('/dem/position')
        if (.not. found) return
        call shape_of(file, '/dem/particles/radius', d, error)
        if (allocated(error)) return
        self%n = d(1)
    end subroutine disks_survey

    !> Error unless /dem/position holds the stored states.
    subroutine disks_records(self, file, n, error)
        !> The part.
        class(disks_xdmf_t), intent(in) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Stored states.
        integer, intent(in) :: n
        !> Set on a read failure or another number of records.
        type(error_t), allocatable, intent(out) :: error
        call require_records(file, '/dem/position', n, error)
    end subroutine disks_records

    !> The disks of state k as points (their centres) with radius, material, velocity,
    !> rotation and angular velocity.
    subroutine disks_grid(self, x, series, k)
        !> The part (surveyed).
        class(disks_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states.
        class(xdmf_series_t), intent(in) :: series
        !> State.
        integer, intent(in) :: k
        integer :: n, r
        n = self%n
        r = series%n_states
        call series%begin_state(x, self%name(), k)
        call x%topology('Polyvertex', n)
        call x%geometry('XY', xdmf_slab('/dem/position', [r, n, 3], [k - 1, 0, 0], [1, n, 2]))
        call x%attribute('radius', 'Scalar', 'Node', xdmf_whole('/dem/particles/radius', [n]))
        call x%attribute('material', 'Scalar', 'Node', xdmf_whole('/dem/particles/material', [n], is_integer=.true.))
        call x%attribute('velocity', 'Vector', 'Node', xdmf_slab('/dem/velocity', [r, n, 3], [k - 1, 0, 0], [1, n, 2]))
        call x%attribute('rotation', 'Scalar', 'Node', xdmf_slab('/dem/position', [r, n, 3], [k - 1, 0, 2], [1, n, 1]))
        call x%attribute('angular_velocity', 'Scalar', 'Node', &
                         xdmf_slab('/dem/velocity', [r, n, 3], [k - 1, 0, 2], [1, n, 1]))
        call x%end_grid()
    end subroutine disks_grid

    !> 'walls'.
    function walls_name(self) result(name)
        !> The part.
        class(walls_xdmf_t), intent(in) :: self
        !> Name of the part.
        character(len=:), allocatable :: name
        name = 'walls'
    end function walls_name

    !> Whether the results file has walls, and how many.
    subroutine walls_survey(self, file, found, error)
        !> The part.
        class(walls_xdmf_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Whether the file has walls.
        logical, intent(out) :: found
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:)
        found = file%exists('/dem/walls/position')
        if (.not. found) return
        call shape_of(file, '/dem/walls/material', d, error)
        if (allocated(error)) return
        self%n = d(1)
    end subroutine walls_survey

    !> Error unless /dem/walls/position holds the stored states.
    subroutine walls_records(self, file, n, error)
        !> The part.
        class(walls_xdmf_t), intent(in) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Stored states.
        integer, intent(in) :: n
        !> Set on a read failure or another number of records.
        type(error_t), allocatable, intent(out) :: error
        call require_records(file, '/dem/walls/position', n, error)
    end subroutine walls_records

    !> The walls of state k as segments (x1 y1 x2 y2 of each wall: two points), with their
    !> material.
    subroutine walls_grid(self, x, series, k)
        !> The part (surveyed).
        class(walls_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states.
        class(xdmf_series_t), intent(in) :: series
        !> State.
        integer, intent(in) :: k
        integer :: n
        n = self%n
        call series%begin_state(x, self%name(), k)
        call x%topology('Polyline', n)
        call x%geometry('XY', xdmf_slab('/dem/walls/position', [series%n_states, n, 4], [k - 1, 0, 0], [1, n, 4]))
        call x%attribute('material', 'Scalar', 'Cell', xdmf_whole('/dem/walls/material', [n], is_integer=.true.))
        call x%end_grid()
    end subroutine walls_grid
end module driver_xdmf_dem
