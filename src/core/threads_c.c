/* OpenBLAS's thread count for core_threads (src/core/threads.f90).
 *
 * OpenBLAS threads its dense kernels (those of CHOLMOD's supernodes, LAPACK's) by its own
 * count, taken from OPENBLAS_NUM_THREADS or else from OMP_NUM_THREADS or the number of
 * cores, and the rounding of a threaded kernel depends on that count: a run would then
 * depend on the cores it was given even where MULTICOR's own loops do not split. The
 * symbols are weak, so that a BLAS other than OpenBLAS (no such functions) links and runs
 * too: it is then left as it is. A weak reference does not pull the functions out of a
 * static libopenblas.a either: a static build leaves OpenBLAS as it is, and says so.
 * OpenBLAS built with OpenMP (Debian's libopenblas0-openmp) sets the OpenMP thread count
 * too (omp_set_num_threads, in goto_set_num_threads): core_threads restores it. */
extern void openblas_set_num_threads(int) __attribute__((weak));
extern int openblas_get_num_threads(void) __attribute__((weak));

/* One thread for OpenBLAS; 1 when done, 0 when the BLAS is not OpenBLAS. */
int multicor_blas_single_thread(void)
{
    if (openblas_set_num_threads == 0) return 0;
    openblas_set_num_threads(1);
    return 1;
}

/* OpenBLAS's thread count; 0 when the BLAS is not OpenBLAS (or not linked dynamically). */
int multicor_blas_threads(void)
{
    if (openblas_get_num_threads == 0) return 0;
    return openblas_get_num_threads();
}
