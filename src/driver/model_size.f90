!> The memory a model will need, estimated from the deck before anything is built, against the
!> memory available (driver_run_checks::check_model_size).
!>
!> Each kind of run adds the parts of its model to a `size_estimate_t` (its
!> `simulation_t%size_estimate`: the beam its nodes and elements, the particles their disks, the
!> continuum its elements; a coupled run both of its parts'): counts of explicit records with
!> `add_count`, generator records (lattice, row, deposit, beam line, continuum mesh) with
!> `add_record`, which also keeps the records that ask for the most memory, the most disks and
!> the most beam nodes, for the messages. `check_size_estimate` then refuses a model with more
!> disks or beam nodes than a run can number, or whose estimate exceeds the available memory,
!> each error at the line of its record.
module driver_model_size
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str, gib
    use io_deck, only: deck_t, deck_entry_t
    implicit none
    private
    public :: model_size_t, model_memory_bytes, check_memory
    public :: size_estimate_t, check_size_estimate
    public :: bytes_per_disk, bytes_per_node, bytes_per_element, bytes_per_q4, bytes_per_t3

    !> Peak memory per disk of a run [bytes]: state, properties and work arrays, detection
    !> grid, contact candidates, the Anderson history, output buffers. Measured: 0.79 kB per
    !> disk on a 90,000-disk lattice at rest (maximum resident size, minus that of a 900-disk
    !> run), but 2.6 kB per disk on a settling deposit of 100 000 disks with the default
    !> solver (Anderson 5) once 2.5 contacts per disk are active (280 MB against a 22 MB base
    !> at step 500; an audit found the earlier figure of 1 kB a third of the peak).
    integer(i8), parameter :: bytes_per_disk = 3000
    !> Peak memory per beam node [bytes]: 3 DOFs, band matrices (stiffness, mass, effective
    !> matrix) and state vectors. Measured: 1.28 kB per node and element of a 100,000-element
    !> beam run (same difference as for the disks).
    integer(i8), parameter :: bytes_per_node = 1200
    !> Peak memory per element [bytes] (connectivity, section, element matrices).
    integer(i8), parameter :: bytes_per_element = 200
    !> Peak memory per Q4 element of the continuum [bytes]: element triplets, sparse stiffness
    !> and mass, CHOLMOD factor, state vectors. Measured: 10.1 to 10.2 kB per element (maximum
    !> resident size of static and dynamic runs on rectangle meshes of 100 x 100, 200 x 200 and
    !> 300 x 300 Q4, differences between them); the factor's fill grows like log(n), hence the
    !> margin.
    integer(i8), parameter :: bytes_per_q4 = 11000
    !> Peak memory per T3 element of the continuum [bytes]. Measured: 6.3 kB per element (the
    !> same runs with 2 T3 per cell: 12.7 kB per cell, against 10.2 kB for one Q4).
    integer(i8), parameter :: bytes_per_t3 = 7000

    !> Numbers of things a model holds, for its memory estimate.
    type :: model_size_t
        !> Disks.
        integer(i8) :: disks = 0
        !> Beam nodes.
        integer(i8) :: beam_nodes = 0
        !> Beam elements.
        integer(i8) :: beam_elements = 0
        !> Q4 elements of the continuum.
        integer(i8) :: q4 = 0
        !> T3 elements of the continuum.
        integer(i8) :: t3 = 0
    end type model_size_t

    !> The generator record that asks for the most of one kind of part (disks, beam nodes).
    type :: record_count_t
        !> How many it asks for (0: no record yet).
        integer(i8) :: count = 0
        !> Its line (0: none).
        integer :: line = 0
        !> Its keyword ('': none).
        character(len=:), allocatable :: keyword
    end type record_count_t

    !> The counts of a deck's model, summed over its parts without overflow (saturating at
    !> huge(0_i8), where the estimate is refused anyway), and its largest generator records.
    type :: size_estimate_t
        !> Counts of the whole model.
        type(model_size_t) :: total
        !> Memory of the largest generator record so far [bytes] (-1: none).
        integer(i8) :: largest = -1
        !> Index in the deck's entries of that record (0: none).
        integer :: entry = 0
        !> Its line (0: none).
        integer :: line = 0
        !> Its keyword ('': none).
        character(len=:), allocatable :: keyword
        !> The generator record with the most disks.
        type(record_count_t) :: most_disks
        !> The generator record with the most beam nodes.
        type(record_count_t) :: most_beam_nodes
    contains
        !> Add counts that no generator record stands for (disks, nodes, elements given one by one).
        procedure :: add_count => estimate_add_count
        !> Add what a generator record of the deck asks for.
        procedure :: add_record => estimate_add_record
    end type size_estimate_t

contains

    !> See `size_estimate_t%add_count`.
    pure subroutine estimate_add_count(self, part)
        !> The estimate.
        class(size_estimate_t), intent(inout) :: self
        !> Counts to add.
        type(model_size_t), intent(in) :: part
        self%total = add_sizes(self%total, part)
    end subroutine estimate_add_count

    !> See `size_estimate_t%add_record`: the record is kept when it asks for more memory than
    !> those added before, or as much and comes earlier in the deck (the parts of a coupled run
    !> are added one after the other: the record named is that of the deck's order).
    subroutine estimate_add_record(self, part, k, e)
        !> The estimate.
        class(size_estimate_t), intent(inout) :: self
        !> What the record asks for.
        type(model_size_t), intent(in) :: part
        !> Its index in the deck's entries.
        integer, intent(in) :: k
        !> The record.
        type(deck_entry_t), intent(in) :: e
        integer(i8) :: bytes
        self%total = add_sizes(self%total, part)
        bytes = model_memory_bytes(part)
        if (bytes > self%largest .or. (bytes == self%largest .and. k < self%entry)) then
            self%largest = bytes
            self%entry = k
            self%line = e%line
            self%keyword = e%keyword
        end if
        call keep_largest(self%most_disks, part%disks)
        call keep_largest(self%most_beam_nodes, part%beam_nodes)
    contains
        !> Make the record `most` when it asks for more than `most`.
        subroutine keep_largest(most, count)
            type(record_count_t), intent(inout) :: most
            integer(i8), intent(in) :: count
            if (count <= most%count) return
            most%count = count
            most%line = e%line
            most%keyword = e%keyword
        end subroutine keep_largest
    end subroutine estimate_add_record

    !> a + b count by count, each huge(0_i8) when it overflows (counts >= 0).
    pure type(model_size_t) function add_sizes(a, b) result(c)
        type(model_size_t), intent(in) :: a, b
        c%disks = add(a%disks, b%disks)
        c%beam_nodes = add(a%beam_nodes, b%beam_nodes)
        c%beam_elements = add(a%beam_elements, b%beam_elements)
        c%q4 = add(a%q4, b%q4)
        c%t3 = add(a%t3, b%t3)
    contains
        pure integer(i8) function add(x, y)
            integer(i8), intent(in) :: x, y
            if (x > huge(0_i8) - y) then
                add = huge(0_i8)
            else
                add = x + y
            end if
        end function add
    end function add_sizes

    !> Error when the deck's model has more disks or beam nodes than a run can number (naming
    !> the generator record that asks for the most of them), or does not fit in the available
    !> memory (naming the generator record that asks for the most memory).
    subroutine check_size_estimate(deck, estimate, available, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its model's estimate (every part added).
        type(size_estimate_t), intent(in) :: estimate
        !> Available memory [bytes] (-1: unknown).
        integer(i8), intent(in) :: available
        !> Set when the model is too large.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: message, keyword
        call check_count(estimate%total%disks, estimate%most_disks, 'disks')
        if (allocated(error)) return
        call check_count(estimate%total%beam_nodes, estimate%most_beam_nodes, 'beam nodes')
        if (allocated(error)) return
        call check_memory(estimate%total, available, error)
        if (allocated(error)) then
            message = error%message
            keyword = ''
            if (allocated(estimate%keyword)) keyword = estimate%keyword
            call make_input_error(error, deck%file, estimate%line, keyword, message)
        end if
    contains
        !> Error when `total` things exceed huge(0), at the line of the record `most`.
        subroutine check_count(total, most, things)
            integer(i8), intent(in) :: total
            type(record_count_t), intent(in) :: most
            character(len=*), intent(in) :: things
            character(len=:), allocatable :: text, key
            if (total <= huge(0)) return
            text = 'the deck asks for '//to_str(total)//' '//things
            if (most%count > 0 .and. most%count < total) text = text//' ('//to_str(most%count)//' of them from this line)'
            key = ''
            if (allocated(most%keyword)) key = most%keyword
            call make_input_error(error, deck%file, most%line, key, text//', more than a run can number ('// &
                                  to_str(huge(0))//')')
        end subroutine check_count
    end subroutine check_size_estimate

    !> Memory a model will need at its peak [bytes] (see bytes_per_disk, bytes_per_node,
    !> bytes_per_element, bytes_per_q4, bytes_per_t3); huge(0_i8) when that exceeds 2^62 bytes
    !> (the counts may each approach 2^63: summed in real(wp), which cannot overflow).
    pure integer(i8) function model_memory_bytes(counts) result(bytes)
        !> Numbers of disks, nodes and elements.
        type(model_size_t), intent(in) :: counts
        real(wp) :: total
        total = real(bytes_per_disk, wp)*real(counts%disks, wp) + &
                real(bytes_per_node, wp)*real(counts%beam_nodes, wp) + &
                real(bytes_per_element, wp)*real(counts%beam_elements, wp) + &
                real(bytes_per_q4, wp)*real(counts%q4, wp) + real(bytes_per_t3, wp)*real(counts%t3, wp)
        if (total < 2.0_wp**62) then
            bytes = int(total, i8)
        else
            bytes = huge(0_i8)
        end if
    end function model_memory_bytes

    !> Error when the model's estimated memory exceeds what is available (nothing is checked
    !> when the available memory is unknown, `available` < 0).
    subroutine check_memory(counts, available, error)
        !> Numbers of disks, nodes and elements.
        type(model_size_t), intent(in) :: counts
        !> Available memory [bytes] (-1: unknown).
        integer(i8), intent(in) :: available
        !> Set when the model does not fit.
        type(error_t), allocatable, intent(out) :: error
        integer(i8) :: need
        if (available < 0) return
        need = model_memory_bytes(counts)
        if (need <= available) return
        call make_error(error, 'the model needs about '//gib(need)//' of memory ('// &
                        to_str(counts%disks)//' disks, '//to_str(counts%beam_nodes)//' beam nodes, '// &
                        to_str(counts%beam_elements)//' beam elements, '//continuum()//') and only '// &
                        gib(available)//' are available (MemAvailable in /proc/meminfo): make the model '// &
                        'smaller, or run it on a machine with more memory')
    contains
        !> 'n continuum elements', or 'n Q4 and m T3 continuum elements' when both kinds are there.
        function continuum() result(text)
            character(len=:), allocatable :: text
            if (counts%q4 > 0 .and. counts%t3 > 0) then
                text = to_str(counts%q4)//' Q4 and '//to_str(counts%t3)//' T3 continuum elements'
            else
                text = to_str(counts%q4 + counts%t3)//' continuum elements'
            end if
        end function continuum
    end subroutine check_memory
end module driver_model_size
