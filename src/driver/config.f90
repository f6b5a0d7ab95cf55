!> Placeholder: to be written.
module driver_config
    implicit none
    private
end module driver_config
