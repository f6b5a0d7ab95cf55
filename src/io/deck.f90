!> Placeholder: to be written.
module io_deck
    implicit none
    private
end module io_deck
