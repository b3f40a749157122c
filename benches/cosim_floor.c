/* C-level floor of a fixed-step Gauss-Seidel loop, for benches/cosim_loops.py.
 *
 * The FMUs are instantiated and initialized by the Python side (fmpy); this function receives the
 * same list of FMI calls the lean master makes per communication step (get/set of connected values,
 * then doStep of every instance) as a table of function pointers, instance handles and buffers, and
 * runs it n times in C. Compiled by the benchmark script with the system C compiler (not committed as a
 * binary). */
#include <stddef.h>

typedef int (*get_set_fn)(void *c, const unsigned int *vr, size_t n, double *value);
typedef int (*step_fn)(void *c, double t, double h, int no_set_prior);

typedef struct {
    int kind; /* 0 = get, 1 = set, 2 = doStep */
    void *fn;
    void *component;
    const unsigned int *vr;
    size_t n;
    double *buf;
} op_t;

int run_loop(const op_t *ops, size_t n_ops, long n_steps, double t0, double dt) {
    int st = 0;
    for (long k = 0; k < n_steps; k++) {
        double t = t0 + (double)k * dt;
        for (size_t i = 0; i < n_ops; i++) {
            const op_t *o = &ops[i];
            if (o->kind == 2) {
                st |= ((step_fn)o->fn)(o->component, t, dt, 1);
            } else {
                st |= ((get_set_fn)o->fn)(o->component, o->vr, o->n, o->buf);
            }
        }
        if (st > 1) {
            return st;
        }
    }
    return st;
}
