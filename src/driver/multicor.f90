!> MULTICOR command-line driver: parses the command line and runs a deck.
!>
!>     multicor [--output DIR] [--quiet] deck.dat
!>     multicor deck.dat --restart DIR/checkpoint.h5 [--end T] (results in DIR unless --output)
!>     multicor --check deck.dat
!>     multicor --help | --version | --schema-markdown
!>
!> Floating-point exceptions do not stop the program (a Debug build traps them by default):
!> the run checks its state after every step and stops with an error naming the step, the body
!> and a likely cause at the first non-finite value (driver_guards), which a trap would turn
!> into a crash without a message.
program multicor
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use, intrinsic :: ieee_exceptions, only: ieee_status_type, ieee_get_status, ieee_set_status
    use, intrinsic :: ieee_exceptions, only: ieee_set_halting_mode, ieee_overflow, ieee_invalid
    use, intrinsic :: ieee_exceptions, only: ieee_divide_by_zero
    use core_kinds, only: wp
    use core_error, only: error_t, error_internal
    use core_version, only: multicor_version
    use core_signals, only: signal_exit_code, catch_broken_pipe, ignore_file_size_signal
    use core_strings, only: parse_real, is_real_syntax, to_lower
    use core_utf8, only: printable
    use io_deck_schema, only: multicor_schema, schema_markdown
    use io_unit_words, only: unit_hint
    use driver_run, only: run_options_t, run_deck
    use driver_simulation, only: report_to_stdout
    implicit none

    type(run_options_t) :: opts
    type(ieee_status_type) :: fp_status
    type(error_t), allocatable :: error
    character(len=:), allocatable :: arg, text
    integer :: i, n, stopped_by
    logical :: take_output, take_restart, take_end, ok

    ! A closed pipe on standard output (`multicor deck.dat | head -1`) must not kill the run
    ! (its folder would stay locked, its results '.partial'): from here on such a write fails
    ! and the run goes on without printing (driver_simulation, report_to_stdout).
    call catch_broken_pipe(error)
    ! A file size limit (`ulimit -f`) makes a write fail (EFBIG, reported as a write error)
    ! instead of killing the program before its first file is whole (an empty folder lock).
    if (.not. allocated(error)) call ignore_file_size_signal(error)
    if (allocated(error)) then
        write (error_unit, '(a)') 'multicor: error: '//printable(error%message)
        stop 1, quiet = .true.
    end if
    n = command_argument_count()
    take_output = .false.
    take_restart = .false.
    take_end = .false.
    do i = 1, n
        call get_arg(i, arg)
        if (take_restart) then
            if (len_trim(arg) == 0) call usage_error("--restart needs a checkpoint file, got ''")
            opts%restart = arg
            take_restart = .false.
            cycle
        end if
        if (take_end) then
            ! parse_real checks the magnitude before reading: a plain read of '1e999' raises
            ! a floating-point overflow (a crash where it traps), of 'inf'/'nan' a non-finite time
            ! blanks around the value are no part of it (`--end ' 5'`)
            call parse_real(trim(adjustl(arg)), opts%end_time, ok)
            if (.not. (is_real_syntax(trim(adjustl(arg))) .or. is_infinity(arg))) &
                call usage_error("--end needs a time in seconds, got '"//arg(:min(len(arg), 40))// &
                                 "', which is not a number"//unit_hint(trim(adjustl(arg)), '', '--end', 's'))
            if (.not. ok) call usage_error("--end needs a finite time in seconds, got '"// &
                                           arg(:min(len(arg), 40))//"'")
            if (.not. (opts%end_time > 0.0_wp .and. opts%end_time <= huge(1.0_wp))) &
                call usage_error("--end needs a positive time in seconds, got '"//arg(:min(len(arg), 40))//"'")
            take_end = .false.
            cycle
        end if
        if (take_output) then
            ! '' would make the results path '/<name>.h5', at the filesystem root
            if (len_trim(arg) == 0) call usage_error("--output needs a folder name, got ''"// &
                                                     " (use '.' for the current folder)")
            opts%output_dir = arg
            take_output = .false.
            cycle
        end if
        select case (arg)
        case ('-h', '--help')
            call print_help()
            stop
        case ('-V', '--version')
            write (output_unit, '(a)') 'multicor '//multicor_version
            stop
        case ('--schema-markdown')
            call schema_markdown(multicor_schema(), text)
            write (output_unit, '(a)', advance='no') text
            stop
        case ('--check')
            opts%check_only = .true.
        case ('-q', '--quiet')
            opts%quiet = .true.
        case ('-o', '--output')
            ! a repeated option is refused, as a repeated keyword in a deck: which one was meant?
            if (allocated(opts%output_dir)) call usage_error('--output given twice')
            take_output = .true.
        case ('--restart')
            if (allocated(opts%restart)) call usage_error('--restart given twice')
            take_restart = .true.
        case ('--end')
            if (opts%end_time >= 0.0_wp) call usage_error('--end given twice')
            take_end = .true.
        case default
            if (arg(1:1) == '-') call usage_error("unknown option '"//arg//"'")
            if (allocated(opts%deck_path)) call usage_error("more than one deck given ('"// &
                                                            opts%deck_path//"' and '"//arg//"')")
            opts%deck_path = arg
        end select
    end do
    if (take_output) call usage_error('--output needs a folder name')
    if (take_restart) call usage_error('--restart needs a checkpoint file')
    if (take_end) call usage_error('--end needs a time in seconds')
    if (opts%check_only .and. allocated(opts%restart)) call usage_error('--check and --restart exclude each other')
    if (.not. allocated(opts%deck_path)) call usage_error('no deck given')

    call ieee_get_status(fp_status)
    call ieee_set_halting_mode(ieee_overflow, .false.)
    call ieee_set_halting_mode(ieee_invalid, .false.)
    call ieee_set_halting_mode(ieee_divide_by_zero, .false.)
    call run_deck(opts, report_to_stdout, error, stopped_by)
    ! The exceptions raised on the way are handled (guards): back to the quiet flags and the
    ! modes of the start, or the end of the program would signal them again.
    call ieee_set_status(fp_status)
    if (allocated(error) .and. stopped_by /= 0) then
        write (error_unit, '(a)') 'multicor: stopped: '//printable(error%message)
        flush (error_unit)
        stop signal_exit_code(stopped_by), quiet = .true.
    else if (allocated(error)) then
        if (error%kind == error_internal) then
            write (error_unit, '(a)') 'multicor: '//printable(error%message)
            flush (error_unit)
            stop 3, quiet = .true.
        end if
        write (error_unit, '(a)') 'multicor: error: '//printable(error%message)
        flush (error_unit)
        stop 1, quiet = .true.
    end if

contains

    subroutine get_arg(i, value)
        integer, intent(in) :: i
        character(len=:), allocatable, intent(out) :: value
        integer :: length
        call get_command_argument(i, length=length)
        allocate (character(len=length) :: value)
        call get_command_argument(i, value)
    end subroutine get_arg

    !> Whether `text` spells an infinity as a Fortran read takes it (`inf`, `-Infinity`).
    pure logical function is_infinity(text)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: word
        word = to_lower(trim(adjustl(text)))
        if (len(word) > 0) then
            if (scan(word(1:1), '+-') == 1) word = word(2:)
        end if
        is_infinity = word == 'inf' .or. word == 'infinity'
    end function is_infinity

    subroutine usage_error(message)
        character(len=*), intent(in) :: message
        write (error_unit, '(a)') 'multicor: error: '//printable(message)
        ! every option of --help (print_help), in its order
        write (error_unit, '(a)') 'usage: multicor [-o DIR] [-q] [--check] [--restart FILE] [--end T] deck.dat', &
            '       multicor --schema-markdown | -V | -h', &
            "('multicor --help' says what each option does)"
        stop 2, quiet = .true.
    end subroutine usage_error

    subroutine print_help()
        write (output_unit, '(a)') 'MULTICOR '//multicor_version// &
            ' - discrete elements (Contact Dynamics) coupled with beam and 2D finite elements', &
            '', &
            'usage: multicor [options] deck.dat', &
            '', &
            '  -o, --output DIR     results folder (default: results/<deck name>; with --restart,', &
            '                       the checkpoint''s folder)', &
            '  -q, --quiet          no progress lines', &
            '      --check          validate the deck only (nothing is written)', &
            '      --restart FILE   continue the run from a checkpoint (DIR/checkpoint.h5)', &
            '      --end T          end time T [s] instead of the deck''s [time] end', &
            '      --schema-markdown  print the reference of every deck keyword (doc/input.md)', &
            '  -V, --version        print the version', &
            '  -h, --help           print this help', &
            '', &
            'Results: DIR/<deck name>.h5 (HDF5, layout in doc/output.md) and DIR/<deck name>.xdmf', &
            '(the same results for ParaView''s XDMF Reader); plots: postproc/plot_results.py.', &
            'Exit codes: 0 success, 1 error in the deck or the run, 2 bad command line, 3 internal error,', &
            '128 + signal number when SIGTERM (143), SIGINT (130), SIGUSR1 (138), SIGUSR2 (140),', &
            'SIGHUP (129) or SIGXCPU (152, a CPU time limit) stopped the', &
            'run: the results so far are then in DIR/<deck name>.h5.partial, and the state in the', &
            'checkpoint DIR/checkpoint.h5 (continue with --restart DIR/checkpoint.h5).'
    end subroutine print_help
end program multicor
