!> Placeholder: to be written.
module dem_particles
    implicit none
    private
end module dem_particles
