!> A coupled run's disks glued by their centres only (`[coupling] rotation = off`, the
!> default) turn freely: a coupled disk in a frictional contact without rolling resistance
!> then rolls instead of transmitting its friction, and the glued body moves over it as on
!> rollers. An audit's elastic block, glued to a row of disks by its bottom band and driven
!> along a rigid wall at mu = 0.3, carried T/N = 0.0000 with `off` and 0.3000 with `on`.
!> Such a deck is accepted with a warning at the [coupling] lines that says so.
module driver_coupled_rolling
    use core_kinds, only: wp
    use core_strings, only: to_str
    use io_deck, only: deck_t
    use dem_moreau_jean, only: dem_system_t
    implicit none
    private
    public :: free_rolling_warning

contains

    !> The warning for a coupled run whose coupled disks (`coupled`, indices into the disks of
    !> `dem`) turn freely (`rotation_row` false) and have a contact law with friction and no
    !> rolling resistance with a material of a disk or a wall; '' otherwise. `material_id`
    !> gives the deck id of each material.
    function free_rolling_warning(deck, rotation_row, coupled, dem, material_id) result(message)
        !> The deck (file and line of the [coupling] entries).
        type(deck_t), intent(in) :: deck
        !> Whether the coupled disks' rotations are glued too.
        logical, intent(in) :: rotation_row
        !> Indices of the coupled disks.
        integer, intent(in) :: coupled(:)
        !> The particle system (materials of the disks and walls, contact laws).
        type(dem_system_t), intent(in) :: dem
        !> Deck id of each material.
        integer, intent(in) :: material_id(:)
        !> The warning, or ''.
        character(len=:), allocatable :: message
        logical, allocatable :: glued(:), present_(:)
        integer :: a, b, n, line
        message = ''
        if (rotation_row .or. size(coupled) == 0) return
        n = size(dem%materials%mu, 1)
        allocate (glued(n), present_(n), source=.false.)
        glued(dem%particles%mat(coupled)) = .true.
        present_(dem%particles%mat(1:dem%particles%n)) = .true.
        if (dem%walls%n > 0) present_(dem%walls%mat(1:dem%walls%n)) = .true.
        do a = 1, n
            if (.not. glued(a)) cycle
            do b = 1, n
                if (.not. present_(b)) cycle
                if (.not. (dem%materials%mu(a, b) > 0.0_wp .and. dem%materials%rolling(a, b) == 0.0_wp)) cycle
                ! without a rotation line: the thickness line, which every coupled deck has
                line = deck%line('coupling', 'rotation')
                if (line == 0) line = deck%line('coupling', 'thickness')
                message = 'warning: '//deck%file//':'//to_str(line)//': [coupling] rotation = off (the '// &
                          'default) leaves the coupled disks free to turn: in a contact with friction and '// &
                          'no rolling resistance (the law of materials '//to_str(material_id(a))//' and '// &
                          to_str(material_id(b))//', mu = '//to_str(dem%materials%mu(a, b))//') a coupled '// &
                          'disk rolls instead of transmitting its friction, and the glued body moves over '// &
                          'it as on rollers; set rotation = on to glue their rotations too'
                return
            end do
        end do
    end function free_rolling_warning
end module driver_coupled_rolling
