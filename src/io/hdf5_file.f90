!> Placeholder: to be written.
module io_hdf5_file
    implicit none
    private
end module io_hdf5_file
