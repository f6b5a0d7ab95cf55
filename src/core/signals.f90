!> Stop requests from the operating system: SIGTERM (Slurm at the time limit, `kill`),
!> SIGINT (Ctrl-C), SIGUSR1 (`sbatch --signal=USR1@120`, sent before the time limit), SIGUSR2
!> (LSF's warning before its time limit, `bsub -wa USR2 -wt 2`), SIGHUP (the terminal of an
!> interactive run closed, an ssh session lost) and SIGXCPU (a CPU time limit's warning before
!> SIGKILL: the soft limit of `ulimit -S -t`, SGE's `s_cpu`). SIGQUIT (Ctrl-\) keeps its
!> default action: a user's "quit now".
!>
!> `install_signal_handlers` installs a handler (src/core/signals_c.c) that only records the
!> first signal caught; the time loops poll `caught_signal()` once per step, finish the step,
!> write a checkpoint, store the step and close the results (doc/output.md, "Interrupted
!> runs"). A second Ctrl-C (SIGINT) stops the program at once (its default action again after
!> the first delivery); a second SIGTERM, SIGUSR1, SIGUSR2, SIGHUP or SIGXCPU is the same
!> request again (Slurm sends SIGTERM twice at a time limit, the kernel SIGXCPU every second past
!> the soft limit). SIGXFSZ is ignored from the program's start
!> (`ignore_file_size_signal`), so that a file size limit (`ulimit -f`) gives a write error
!> instead of killing the program. The flag lives in the C file (a signal handler can
!> only set a `volatile sig_atomic_t`); this module keeps no state.
!>
!> SIGPIPE, a write to a pipe whose reader has gone (`multicor deck.dat | head -1`, a `tee`
!> that died), is caught from the program's start (`catch_broken_pipe`) and recorded apart:
!> the write fails instead of killing the program, which leaves its results folder locked
!> and its results '.partial'. `broken_pipe()` then tells the printing routine to print no
!> more (the lines are progress, not results; gfortran keeps every line that failed in the
!> unit's buffer): the run goes on to its end, or to a stop signal, as if `--quiet`.
module core_signals
    use, intrinsic :: iso_c_binding, only: c_int
    use core_error, only: error_t, make_error
    implicit none
    private
    public :: install_signal_handlers, caught_signal, signal_name, clear_caught_signal, &
              signal_exit_code, stop_signals, catch_broken_pipe, broken_pipe, clear_broken_pipe, &
              broken_pipe_signal, ignore_file_size_signal

    interface
        !> Install the handlers (0 on success).
        integer(c_int) function c_install() bind(c, name='multicor_signals_install')
            import :: c_int
        end function c_install
        !> First signal caught, 0 if none.
        integer(c_int) function c_caught() bind(c, name='multicor_signals_caught')
            import :: c_int
        end function c_caught
        !> Forget the caught signal.
        subroutine c_clear() bind(c, name='multicor_signals_clear')
        end subroutine c_clear
        !> Ignore SIGXFSZ (0 on success).
        integer(c_int) function c_sigxfsz_ignore() bind(c, name='multicor_sigxfsz_ignore')
            import :: c_int
        end function c_sigxfsz_ignore
        !> Install the SIGPIPE handler (0 on success).
        integer(c_int) function c_sigpipe_install() bind(c, name='multicor_sigpipe_install')
            import :: c_int
        end function c_sigpipe_install
        !> 1 once a SIGPIPE was caught, else 0.
        integer(c_int) function c_pipe_broken() bind(c, name='multicor_pipe_broken_get')
            import :: c_int
        end function c_pipe_broken
        !> Forget a caught SIGPIPE.
        subroutine c_pipe_clear() bind(c, name='multicor_pipe_broken_clear')
        end subroutine c_pipe_clear
        !> SIGPIPE of this platform.
        integer(c_int) function c_sigpipe() bind(c, name='multicor_sigpipe')
            import :: c_int
        end function c_sigpipe
        !> SIGTERM of this platform.
        integer(c_int) function c_sigterm() bind(c, name='multicor_sigterm')
            import :: c_int
        end function c_sigterm
        !> SIGINT of this platform.
        integer(c_int) function c_sigint() bind(c, name='multicor_sigint')
            import :: c_int
        end function c_sigint
        !> SIGUSR1 of this platform.
        integer(c_int) function c_sigusr1() bind(c, name='multicor_sigusr1')
            import :: c_int
        end function c_sigusr1
        !> SIGHUP of this platform.
        integer(c_int) function c_sighup() bind(c, name='multicor_sighup')
            import :: c_int
        end function c_sighup
        !> SIGUSR2 of this platform.
        integer(c_int) function c_sigusr2() bind(c, name='multicor_sigusr2')
            import :: c_int
        end function c_sigusr2
        !> SIGXCPU of this platform.
        integer(c_int) function c_sigxcpu() bind(c, name='multicor_sigxcpu')
            import :: c_int
        end function c_sigxcpu
    end interface

contains

    !> Catch SIGTERM, SIGINT, SIGUSR1, SIGUSR2, SIGHUP and SIGXCPU from now on.
    subroutine install_signal_handlers(error)
        !> Set when the operating system refuses a handler.
        type(error_t), allocatable, intent(out) :: error
        if (c_install() /= 0) call make_error(error, 'cannot install the signal handlers '// &
                                              '(SIGTERM, SIGINT, SIGUSR1, SIGUSR2, SIGHUP, SIGXCPU)')
    end subroutine install_signal_handlers

    !> Ignore SIGXFSZ from now on: a write beyond the file size limit (`ulimit -f`) fails
    !> with EFBIG, reported as a write error, instead of killing the program.
    subroutine ignore_file_size_signal(error)
        !> Set when the operating system refuses it.
        type(error_t), allocatable, intent(out) :: error
        if (c_sigxfsz_ignore() /= 0) call make_error(error, 'cannot ignore the signal SIGXFSZ')
    end subroutine ignore_file_size_signal

    !> Catch SIGPIPE from now on: a write to a pipe without reader fails (EPIPE) and is
    !> recorded (`broken_pipe`) instead of killing the program.
    subroutine catch_broken_pipe(error)
        !> Set when the operating system refuses the handler.
        type(error_t), allocatable, intent(out) :: error
        if (c_sigpipe_install() /= 0) call make_error(error, 'cannot install the signal handler (SIGPIPE)')
    end subroutine catch_broken_pipe

    !> Whether a write went to a pipe whose reader has gone (SIGPIPE caught) since the start.
    logical function broken_pipe()
        broken_pipe = c_pipe_broken() /= 0
    end function broken_pipe

    !> Forget a caught SIGPIPE (for tests).
    subroutine clear_broken_pipe()
        call c_pipe_clear()
    end subroutine clear_broken_pipe

    !> SIGPIPE's number on this platform (for tests).
    integer function broken_pipe_signal()
        broken_pipe_signal = int(c_sigpipe())
    end function broken_pipe_signal

    !> Number of the first stop signal caught since the start (0: none).
    integer function caught_signal()
        caught_signal = int(c_caught())
    end function caught_signal

    !> Forget a caught signal (for tests).
    subroutine clear_caught_signal()
        call c_clear()
    end subroutine clear_caught_signal

    !> Name of a signal number: 'SIGTERM', 'SIGINT', 'SIGUSR1', 'SIGUSR2', 'SIGHUP', 'SIGXCPU',
    !> or 'signal <n>'.
    function signal_name(sig) result(name)
        !> Signal number.
        integer, intent(in) :: sig
        !> Its name.
        character(len=:), allocatable :: name
        character(len=16) :: buf
        if (sig == int(c_sigterm())) then
            name = 'SIGTERM'
        else if (sig == int(c_sigint())) then
            name = 'SIGINT'
        else if (sig == int(c_sigusr1())) then
            name = 'SIGUSR1'
        else if (sig == int(c_sighup())) then
            name = 'SIGHUP'
        else if (sig == int(c_sigusr2())) then
            name = 'SIGUSR2'
        else if (sig == int(c_sigxcpu())) then
            name = 'SIGXCPU'
        else
            write (buf, '(a,i0)') 'signal ', sig
            name = trim(buf)
        end if
    end function signal_name

    !> Numbers of the stop signals of this platform: SIGTERM, SIGINT, SIGUSR1, SIGHUP, SIGUSR2,
    !> SIGXCPU.
    function stop_signals() result(sigs)
        !> The six numbers, in that order.
        integer :: sigs(6)
        sigs = [int(c_sigterm()), int(c_sigint()), int(c_sigusr1()), int(c_sighup()), int(c_sigusr2()), &
                int(c_sigxcpu())]
    end function stop_signals

    !> Exit code of a run stopped by a signal: 128 + the signal number, the shell's
    !> convention (SIGTERM 143, SIGINT 130, SIGUSR1 138, SIGUSR2 140, SIGHUP 129, SIGXCPU 152
    !> on Linux).
    pure integer function signal_exit_code(sig)
        !> Signal number.
        integer, intent(in) :: sig
        signal_exit_code = 128 + sig
    end function signal_exit_code
end module core_signals
