/* Signal handling for core_signals (src/core/signals.f90).
 *
 * SIGTERM, SIGINT, SIGUSR1, SIGUSR2, SIGHUP and SIGXCPU set a flag and nothing else (the only
 * thing a handler may safely do); the time loops poll it once per step and stop cleanly. SIGINT
 * alone has SA_RESETHAND, its default action back after the first delivery: a second Ctrl-C
 * kills the program at once. A repeated SIGTERM, SIGUSR1, SIGUSR2, SIGHUP or SIGXCPU is only
 * the same request again:
 * Slurm at a job's time limit sends a step's processes SIGTERM twice within milliseconds
 * (slurmstepd and srun), which killed the run before its checkpoint; SIGKILL is the way to
 * stop at once (Slurm sends it after KillWait). SIGHUP (the terminal of an interactive run
 * closed, an ssh session lost) stops the run as SIGTERM does, with its checkpoint, instead of killing it;
 * under `nohup` (SIGHUP ignored when the program starts) it stays ignored, and so does a
 * SIGINT ignored at the start (the results file stays readable up to its last flush).
 * SIGUSR2 is the warning signal of LSF (`bsub -wa USR2 -wt ...`) and SIGXCPU that of a CPU time
 * limit (the soft limit of `ulimit -S -t`, SGE's `s_cpu`), sent before SIGKILL; the kernel
 * repeats SIGXCPU every second of CPU time past the soft limit, each one the same request. Their
 * default actions killed the run (SIGXCPU with a core dump, and gfortran's backtrace, whose
 * handler this one replaces). SIGQUIT (Ctrl-\, "quit now") keeps its default action.
 * SIGXFSZ (file size limit, `ulimit -f`) is ignored from the program's start, so that
 * exceeding the limit makes the write fail with EFBIG and is reported like a full disk instead
 * of killing the process (ignored only once the handlers were installed, it killed a run under
 * `ulimit -f 0` at the lock file's first write, which left that lock empty).
 *
 * SIGPIPE (a write to a pipe whose reader is gone: `multicor deck.dat | head -1`) sets a
 * flag of its own and keeps its handler: the write fails with EPIPE instead of killing the
 * program, and the program stops printing (its lines are not its results) and goes on. A
 * handler rather than SIG_IGN: an ignored signal would stay ignored in child processes. */
#include <signal.h>
#include <string.h>

static volatile sig_atomic_t multicor_caught = 0;
static volatile sig_atomic_t multicor_pipe_broken = 0;

static void multicor_on_signal(int sig)
{
    if (multicor_caught == 0) multicor_caught = sig;
}

static void multicor_on_sigpipe(int sig)
{
    (void)sig;
    multicor_pipe_broken = 1;
}

/* Install the handlers; 0 on success, -1 when sigaction fails. */
int multicor_signals_install(void)
{
    static const int handled[] = {SIGTERM, SIGINT, SIGUSR1, SIGUSR2, SIGHUP, SIGXCPU};
    struct sigaction sa;
    size_t k;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = multicor_on_signal;
    sigemptyset(&sa.sa_mask);
    for (k = 0; k < sizeof handled / sizeof handled[0]; ++k) {
        sa.sa_flags = handled[k] == SIGINT ? SA_RESETHAND | SA_RESTART : SA_RESTART;
        /* A SIGHUP or SIGINT ignored by whoever started the program stays ignored: `nohup`
         * (a run meant to outlive its terminal), a job started in the background by a
         * non-interactive shell (Ctrl-C in the terminal is not for it). */
        if (handled[k] == SIGHUP || handled[k] == SIGINT) {
            struct sigaction old;
            if (sigaction(handled[k], NULL, &old) != 0) return -1;
            if (old.sa_handler == SIG_IGN) continue;
        }
        if (sigaction(handled[k], &sa, NULL) != 0) return -1;
    }
    return 0;
}

/* Ignore SIGXFSZ from now on; 0 on success, -1 when sigaction fails. */
int multicor_sigxfsz_ignore(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = SIG_IGN;
    sigemptyset(&sa.sa_mask);
    return sigaction(SIGXFSZ, &sa, NULL) == 0 ? 0 : -1;
}

/* Catch SIGPIPE from now on (every delivery: no SA_RESETHAND); 0 on success, -1 when
 * sigaction fails. */
int multicor_sigpipe_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = multicor_on_sigpipe;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    return sigaction(SIGPIPE, &sa, NULL) == 0 ? 0 : -1;
}

/* 1 once a SIGPIPE was caught, else 0. */
int multicor_pipe_broken_get(void) { return (int)multicor_pipe_broken; }

/* Forget a caught SIGPIPE (tests only). */
void multicor_pipe_broken_clear(void) { multicor_pipe_broken = 0; }

/* SIGPIPE of this platform. */
int multicor_sigpipe(void) { return SIGPIPE; }

/* Number of the first signal caught (0: none). */
int multicor_signals_caught(void) { return (int)multicor_caught; }

/* Forget a caught signal (tests only; SIGINT's handler stays reset after its first delivery). */
void multicor_signals_clear(void) { multicor_caught = 0; }

/* Signal numbers of this platform. */
int multicor_sigterm(void) { return SIGTERM; }
int multicor_sigint(void) { return SIGINT; }
int multicor_sigusr1(void) { return SIGUSR1; }
int multicor_sighup(void) { return SIGHUP; }
int multicor_sigusr2(void) { return SIGUSR2; }
int multicor_sigxcpu(void) { return SIGXCPU; }
