/* A hostile FMI 2.0 master in C: loads an FMU binary with dlopen and drives it the way a careless or
 * malicious tool would. Each mode prints one summary line "ok ..." and exits 0, or prints what went
 * wrong and exits 1. Run under valgrind / a timeout by tests/test_hardening.py.
 *
 *   fmi_hostile LIB GUID cycles N        instantiate/init/step/state/serialize/free N times
 *   fmi_hostile LIB GUID reload N        dlopen + one instance + dlclose, N times
 *   fmi_hostile LIB GUID threads T N     T threads, N cycles each (with state reuse), results compared
 *   fmi_hostile LIB GUID hang            calls that used to run forever must return an error promptly
 *   fmi_hostile LIB GUID fuzz N SEED     serialized states with random bytes and a valid CRC
 *   fmi_hostile LIB GUID extreme         extreme parameters: errors, never infinite values with fmi2OK
 *   fmi_hostile LIB GUID race N          deliberate misuse: two threads call ONE instance at the same time
 *                                        (FMI forbids it); under ThreadSanitizer this must be reported, which
 *                                        shows the detector is live (results are not checked)
 *
 * LIB must be an AttitudePlant binary (value references from modelDescription/AttitudePlant.xml).
 */
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *C;
typedef int St;
enum { OK = 0, WARNING = 1, DISCARD = 2, ERROR = 3, FATAL = 4 };
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*alloc)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;

typedef struct {
    void *lib;
    C (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    void (*free_instance)(C);
    St (*setup)(C, int, double, double, int, double);
    St (*enter_init)(C);
    St (*exit_init)(C);
    St (*set_real)(C, const unsigned *, size_t, const double *);
    St (*get_real)(C, const unsigned *, size_t, double *);
    St (*set_integer)(C, const unsigned *, size_t, const int *);
    St (*do_step)(C, double, double, int);
    St (*get_state)(C, void **);
    St (*set_state)(C, void *);
    St (*free_state)(C, void **);
    St (*ser_size)(C, void *, size_t *);
    St (*serialize)(C, void *, char *, size_t);
    St (*deserialize)(C, const char *, size_t, void **);
} Fmi;

#if defined(__SANITIZE_THREAD__)
/* A Rust library built with -Zsanitizer=thread calls __tsan_memcpy/__tsan_memmove/__tsan_memset, which
 * LLVM's TSan runtime has and GCC 12's libtsan does not. Here they forward to the C functions, which
 * libtsan intercepts (so the accesses are still checked); build with -rdynamic so that the dlopen'ed
 * library finds them. */
void *__tsan_memcpy(void *d, const void *s, size_t n) { return memcpy(d, s, n); }
void *__tsan_memmove(void *d, const void *s, size_t n) { return memmove(d, s, n); }
void *__tsan_memset(void *d, int c, size_t n) { return memset(d, c, n); }
#endif

/* AttitudePlant value references */
enum { VR_TORQUE_CMD_X = 0, VR_Q_W = 10, VR_W_X = 14, VR_MAX_STEP = 130, VR_INTEGRATOR = 140, VR_ACTUATOR_MODE = 142,
       VR_WHEEL_COEFF = 153, VR_WHEEL_CURRENT = 154, VR_ORBIT_RADIUS = 161, VR_INIT_W_X = 113, VR_NOISE_STD_X = 180 };

static const char *LIB, *GUID;
static int quiet_logger_count;

static void logger(void *env, const char *name, int status, const char *cat, const char *msg, ...) {
    (void)env; (void)name; (void)cat;
    if (getenv("HOSTILE_VERBOSE")) fprintf(stderr, "[%d] %s\n", status, msg);
    __atomic_add_fetch(&quiet_logger_count, 1, __ATOMIC_RELAXED);
}
static const Callbacks CB = {logger, calloc, free, NULL, NULL};

static void die(const char *what) { printf("FAIL %s\n", what); fflush(stdout); exit(1); }
#define CHECK(cond, what) do { if (!(cond)) die(what); } while (0)

static void *sym(void *lib, const char *name) {
    void *p = dlsym(lib, name);
    if (!p) { printf("FAIL missing symbol %s\n", name); exit(1); }
    return p;
}

static Fmi load(void) {
    Fmi f;
    f.lib = dlopen(LIB, RTLD_NOW | RTLD_LOCAL);
    if (!f.lib) { printf("FAIL dlopen %s: %s\n", LIB, dlerror()); exit(1); }
    f.instantiate = sym(f.lib, "fmi2Instantiate");
    f.free_instance = sym(f.lib, "fmi2FreeInstance");
    f.setup = sym(f.lib, "fmi2SetupExperiment");
    f.enter_init = sym(f.lib, "fmi2EnterInitializationMode");
    f.exit_init = sym(f.lib, "fmi2ExitInitializationMode");
    f.set_real = sym(f.lib, "fmi2SetReal");
    f.get_real = sym(f.lib, "fmi2GetReal");
    f.set_integer = sym(f.lib, "fmi2SetInteger");
    f.do_step = sym(f.lib, "fmi2DoStep");
    f.get_state = sym(f.lib, "fmi2GetFMUstate");
    f.set_state = sym(f.lib, "fmi2SetFMUstate");
    f.free_state = sym(f.lib, "fmi2FreeFMUstate");
    f.ser_size = sym(f.lib, "fmi2SerializedFMUstateSize");
    f.serialize = sym(f.lib, "fmi2SerializeFMUstate");
    f.deserialize = sym(f.lib, "fmi2DeSerializeFMUstate");
    return f;
}

static C ready(const Fmi *f, int noise) {
    C c = f->instantiate("hostile", 1, GUID, NULL, &CB, 0, 0);
    CHECK(c, "instantiate");
    CHECK(f->setup(c, 0, 0.0, 0.0, 0, 0.0) == OK, "setup");
    CHECK(f->enter_init(c) == OK, "enter init");
    unsigned vr[2] = {VR_INIT_W_X, VR_NOISE_STD_X};
    double v[2] = {0.05, noise ? 0.5 : 0.0};
    CHECK(f->set_real(c, vr, 2, v) == OK, "set parameters");
    CHECK(f->exit_init(c) == OK, "exit init");
    return c;
}

static void step_n(const Fmi *f, C c, double *t, int n) {
    unsigned vr = VR_TORQUE_CMD_X;
    for (int k = 0; k < n; k++) {
        double u = 3.0 * sin(*t);
        CHECK(f->set_real(c, &vr, 1, &u) == OK, "set input");
        CHECK(f->do_step(c, *t, 0.01, 1) == OK, "doStep");
        *t += 0.01;
    }
}

static double read_wx(const Fmi *f, C c) {
    unsigned vr = VR_W_X;
    double w = NAN;
    CHECK(f->get_real(c, &vr, 1, &w) == OK, "get output");
    return w;
}

static char *serialize(const Fmi *f, C c, void *s, size_t *n) {
    CHECK(f->ser_size(c, s, n) == OK, "serialized size");
    char *b = malloc(*n);
    CHECK(f->serialize(c, s, b, *n) == OK, "serialize");
    return b;
}

/* one full cycle: returns w_x at t = 0.15 s. Both variants restore a state and continue to the same
   end time, so they must agree bit for bit with each other and with an uninterrupted run. */
static double cycle(const Fmi *f, int reuse) {
    C c = ready(f, 1);
    double t = 0.0;
    step_n(f, c, &t, 5);
    double t_saved = t;
    void *s = NULL;
    CHECK(f->get_state(c, &s) == OK, "get state");
    step_n(f, c, &t, 5);
    if (reuse) {
        CHECK(f->get_state(c, &s) == OK, "get state (reuse)");
        t_saved = t;
    }
    size_t n;
    char *b = serialize(f, c, s, &n);
    void *s2 = NULL;
    CHECK(f->deserialize(c, b, n, &s2) == OK, "deserialize");
    if (reuse) CHECK(f->deserialize(c, b, n, &s) == OK, "deserialize (reuse)");
    CHECK(f->set_state(c, s2) == OK, "set state");
    t = t_saved;
    step_n(f, c, &t, reuse ? 5 : 10);
    double w = read_wx(f, c);
    free(b);
    CHECK(f->free_state(c, &s2) == OK, "free state");
    /* s is freed with the instance */
    f->free_instance(c);
    return w;
}

/* ----- CRC-32 (IEEE), as used by the state format ----- */
static uint32_t crc32(const unsigned char *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}
static void fix_crc(unsigned char *b, size_t n) {
    uint32_t crc = crc32(b, n - 4);
    memcpy(b + n - 4, &crc, 4); /* little endian host */
}

static uint64_t rng;
static uint64_t next(void) { rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17; return rng; }

/* a restored state must either be refused or give a usable instance (step returns, finite outputs) */
static int try_state(const Fmi *f, C c, unsigned char *b, size_t n, int *accepted) {
    void *s = NULL;
    St st = f->deserialize(c, (const char *)b, n, &s);
    if (st != OK) { CHECK(st == ERROR, "deserialize returned neither OK nor Error"); return 0; }
    (*accepted)++;
    CHECK(f->set_state(c, s) == OK, "set accepted state");
    double t = 0.0;
    unsigned vr = VR_W_X; double w;
    /* the restored time may be anything finite: read it back through a step at that time is not possible
       without fmi2GetRealStatus; stepping from a wrong time is refused, which is fine */
    St g = f->get_real(c, &vr, 1, &w);
    CHECK(g == OK || g == ERROR, "get after restore");
    if (g == OK) CHECK(isfinite(w), "fmi2OK with a non-finite output");
    (void)t;
    f->free_state(c, &s);
    return 1;
}

/* race mode: two threads on one instance (forbidden by FMI), to check that ThreadSanitizer reports it */
typedef struct { const Fmi *f; C c; int n; int writer; } Racer;
static void *racer(void *arg) {
    Racer *r = (Racer *)arg;
    unsigned in = VR_TORQUE_CMD_X, out = VR_W_X;
    for (int i = 0; i < r->n; i++) {
        double v = 1e-3 * i;
        if (r->writer) r->f->set_real(r->c, &in, 1, &v); else r->f->get_real(r->c, &out, 1, &v);
    }
    return NULL;
}

/* threads mode: each thread runs its own instances (with state reuse) and compares with the reference */
typedef struct { const Fmi *f; int n; double ref; int bad; } Work;
static void *worker(void *arg) {
    Work *w = (Work *)arg;
    for (int i = 0; i < w->n; i++)
        if (cycle(w->f, i % 2) != w->ref) w->bad = 1;
    return NULL;
}

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: %s LIB GUID MODE ...\n", argv[0]); return 2; }
    LIB = argv[1]; GUID = argv[2];
    const char *mode = argv[3];
    if (!strcmp(mode, "cycles")) {
        int n = atoi(argv[4]);
        Fmi f = load();
        double w0 = cycle(&f, 0);
        for (int i = 1; i < n; i++) CHECK(cycle(&f, i % 2) == w0, "cycles not bit-identical");
        dlclose(f.lib);
        printf("ok cycles %d w_x %.17g\n", n, w0);
    } else if (!strcmp(mode, "reload")) {
        int n = atoi(argv[4]);
        double w0 = 0.0;
        for (int i = 0; i < n; i++) {
            Fmi f = load();
            double w = cycle(&f, 1);
            if (i == 0) w0 = w; else CHECK(w == w0, "reload not bit-identical");
            CHECK(dlclose(f.lib) == 0, "dlclose");
        }
        printf("ok reload %d\n", n);
    } else if (!strcmp(mode, "threads")) {
        int nt = atoi(argv[4]), n = atoi(argv[5]);
        CHECK(nt > 0 && nt <= 64, "1 to 64 threads");
        Fmi f = load();
        double ref = cycle(&f, 1);
        pthread_t th[64];
        Work w[64];
        for (int i = 0; i < nt; i++) {
            w[i] = (Work){&f, n, ref, 0};
            CHECK(pthread_create(&th[i], NULL, worker, &w[i]) == 0, "pthread_create");
        }
        for (int i = 0; i < nt; i++) pthread_join(th[i], NULL);
        for (int i = 0; i < nt; i++) CHECK(w[i].bad == 0, "a thread's result differs from the single-threaded run");
        dlclose(f.lib);
        printf("ok threads %d x %d cycles, all bit-identical to the single-threaded run\n", nt, n);
    } else if (!strcmp(mode, "race")) {
        int n = atoi(argv[4]);
        Fmi f = load();
        C c = ready(&f, 0);
        Racer r[2] = {{&f, c, n, 1}, {&f, c, n, 0}};
        pthread_t th[2];
        for (int i = 0; i < 2; i++) CHECK(pthread_create(&th[i], NULL, racer, &r[i]) == 0, "pthread_create");
        for (int i = 0; i < 2; i++) pthread_join(th[i], NULL);
        f.free_instance(c);
        dlclose(f.lib);
        printf("ok race %d calls per thread on one instance (misuse)\n", n);
    } else if (!strcmp(mode, "hang")) {
        Fmi f = load();
        /* 1. a tiny internal step is refused at initialization (declared range) */
        C c = f.instantiate("h1", 1, GUID, NULL, &CB, 0, 0);
        f.setup(c, 0, 0, 0, 0, 0); f.enter_init(c);
        unsigned vr = VR_MAX_STEP; double v = 1e-300;
        CHECK(f.set_real(c, &vr, 1, &v) == OK, "set max step");
        CHECK(f.exit_init(c) == ERROR, "max_internal_step = 1e-300 accepted");
        /* 2. the smallest allowed step with a long communication step is refused before the work */
        v = 1e-6; f.set_real(c, &vr, 1, &v);
        CHECK(f.exit_init(c) == OK, "exit init with 1e-6");
        CHECK(f.do_step(c, 0.0, 10.0, 1) == ERROR, "doStep needing 1e7 internal steps accepted");
        f.free_instance(c);
        /* 3. default parameters, a step of 1e12 s */
        c = ready(&f, 0);
        CHECK(f.do_step(c, 0.0, 1e12, 1) == ERROR, "doStep(0, 1e12) accepted");
        f.free_instance(c);
        /* 4. adaptive integrator with an absurd tolerance: bounded */
        c = f.instantiate("h4", 1, GUID, NULL, &CB, 0, 0);
        f.setup(c, 1, 1e-300, 0.0, 0, 0.0); f.enter_init(c);
        unsigned iv = VR_INTEGRATOR; int two = 2;
        f.set_integer(c, &iv, 1, &two);
        unsigned wv = VR_INIT_W_X; double w = 0.1; f.set_real(c, &wv, 1, &w);
        CHECK(f.exit_init(c) == OK, "exit init DP");
        St st = f.do_step(c, 0.0, 1e6, 1);
        CHECK(st == OK || st == ERROR, "DP long step");
        f.free_instance(c);
        /* 5. a serialized state whose stored internal step is changed (CRC recomputed) is refused */
        c = ready(&f, 0);
        double t = 0; step_n(&f, c, &t, 3);
        void *s = NULL; f.get_state(c, &s);
        size_t n; unsigned char *b = (unsigned char *)serialize(&f, c, s, &n);
        double small = 0.01, evil = 1e-22; int found = 0;
        for (size_t i = 16; i + 8 <= n - 4; i++) {
            if (memcmp(b + i, &small, 8)) continue;
            found++;
            unsigned char *m = malloc(n); memcpy(m, b, n); memcpy(m + i, &evil, 8); fix_crc(m, n);
            void *s2 = NULL;
            CHECK(f.deserialize(c, (char *)m, n, &s2) == ERROR, "state with a changed internal step accepted");
            free(m);
        }
        CHECK(found >= 2, "the internal step value was not found in the payload");
        free(b); f.free_instance(c);
        dlclose(f.lib);
        printf("ok hang (%d stored copies of the step refused)\n", found);
    } else if (!strcmp(mode, "fuzz")) {
        int n = atoi(argv[4]); rng = strtoull(argv[5], NULL, 10) | 1;
        Fmi f = load();
        C c = ready(&f, 1);
        double t = 0; step_n(&f, c, &t, 7);
        void *s = NULL; f.get_state(c, &s);
        size_t len; unsigned char *b = (unsigned char *)serialize(&f, c, s, &len);
        int accepted = 0;
        unsigned char *m = malloc(len);
        for (int i = 0; i < n; i++) {
            memcpy(m, b, len);
            int flips = 1 + (int)(next() % 4);
            for (int k = 0; k < flips; k++) {
                size_t at = 16 + next() % (len - 20);
                if (next() % 2) m[at] ^= (unsigned char)(1u << (next() % 8)); else m[at] = (unsigned char)next();
            }
            fix_crc(m, len);
            try_state(&f, c, m, len, &accepted);
        }
        /* the instance is still usable afterwards */
        CHECK(f.set_state(c, s) == OK, "restore the original state");
        free(m); free(b); f.free_instance(c); dlclose(f.lib);
        printf("ok fuzz %d mutations, %d accepted and usable\n", n, accepted);
    } else if (!strcmp(mode, "extreme")) {
        Fmi f = load();
        struct { unsigned vr[2]; double v[2]; int n; const char *what; } cases[] = {
            {{VR_ORBIT_RADIUS}, {1e-110}, 1, "orbit_radius = 1e-110 (orbit_rate = inf)"},
            {{VR_WHEEL_COEFF, VR_WHEEL_CURRENT}, {1e300, 1e300}, 2, "wheel torque limit 1e600"},
        };
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            C c = f.instantiate("x", 1, GUID, NULL, &CB, 0, 0);
            f.setup(c, 0, 0, 0, 0, 0); f.enter_init(c);
            CHECK(f.set_real(c, cases[i].vr, cases[i].n, cases[i].v) == OK, "set extreme");
            if (f.exit_init(c) != ERROR) die(cases[i].what);
            f.free_instance(c);
        }
        /* huge but finite commands: outputs finite or an error, never OK with inf */
        C c = ready(&f, 0);
        unsigned vr = VR_TORQUE_CMD_X; double u = 1e308;
        f.set_real(c, &vr, 1, &u);
        St st = f.do_step(c, 0.0, 0.01, 1);
        unsigned ov = VR_W_X; double w;
        St g = f.get_real(c, &ov, 1, &w);
        CHECK(st == ERROR || g == ERROR || isfinite(w), "fmi2OK with a non-finite output");
        f.free_instance(c);
        dlclose(f.lib);
        printf("ok extreme\n");
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    return 0;
}

