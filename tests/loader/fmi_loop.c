/* A minimal FMI 2.0 co-simulation master in portable C, built twice by tests/test_win64.py: natively
 * with gcc (loads binaries/linux64/<Model>.so with dlopen) and with x86_64-w64-mingw32-gcc (loads
 * binaries/win64/<Model>.dll with LoadLibrary, run under Wine). Both builds run the same closed loop
 * and print every value with %.17g, so the two platforms' binaries can be compared bit for bit.
 *
 *   fmi_loop PLANT_LIB PLANT_GUID CTRL_LIB CTRL_GUID STEPS DT PLANT_SET CTRL_SET P2C C2P OUT
 *   fmi_loop instantiate LIB GUID      one fmi2Instantiate; prints "instance" or "null" (log on stderr)
 *
 *   PLANT_SET, CTRL_SET  start values set in initialization mode: "vr=value,vr=value" (or "-")
 *   P2C, C2P             wires plant output -> controller input and back: "from:to,from:to" (or "-")
 *   OUT                  plant output value references printed after every step: "vr,vr,..."
 *   environment FMI_LOOP_PLANT_RESOURCES / FMI_LOOP_CONTROLLER_RESOURCES: the fmuResourceLocation passed to
 *                        that FMU's fmi2Instantiate (unset: NULL, which the project's FMUs accept)
 *
 * Sampled-data loop (Jacobi, zero-order hold): at t_k the controller reads the plant outputs and
 * steps; its outputs are fed to the plant, which steps over [t_k, t_k + DT]. Output: one line
 * "fmi2GetTypesPlatform=... fmi2GetVersion=..." then one line per step "k v1 v2 ...", then "ok", where
 * each value is printed as %.17g and its IEEE-754 bit pattern in hex ("0.5:3fe0000000000000"), so a
 * difference in the C library's decimal formatting cannot hide or fake a difference in the numbers.
 * Any failed call prints "FAIL ..." and exits 1.
 */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Lib;
static Lib lib_open(const char *path) { return LoadLibraryA(path); }
static void *lib_sym(Lib l, const char *name) { return (void *)GetProcAddress(l, name); }
static void lib_close(Lib l) { FreeLibrary(l); }
static const char *lib_error(void) {
    static char text[32];
    snprintf(text, sizeof text, "error %lu", (unsigned long)GetLastError());
    return text;
}
#else
#include <dlfcn.h>
typedef void *Lib;
static Lib lib_open(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *lib_sym(Lib l, const char *name) { return dlsym(l, name); }
static void lib_close(Lib l) { dlclose(l); }
static const char *lib_error(void) { return dlerror(); }
#endif

typedef void *C;
typedef int St;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*alloc)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;

typedef struct {
    Lib lib;
    const char *(*types_platform)(void);
    const char *(*version)(void);
    C (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    void (*free_instance)(C);
    St (*setup)(C, int, double, double, int, double);
    St (*enter_init)(C);
    St (*exit_init)(C);
    St (*terminate)(C);
    St (*set_real)(C, const unsigned *, size_t, const double *);
    St (*get_real)(C, const unsigned *, size_t, double *);
    St (*do_step)(C, double, double, int);
} Fmu;

static void logger(void *env, const char *name, int status, const char *cat, const char *msg, ...) {
    (void)env; (void)cat;
    fprintf(stderr, "[%s %d] %s\n", name, status, msg);
}
static const Callbacks CB = {logger, calloc, free, NULL, NULL};

static void die(const char *what) { printf("FAIL %s\n", what); fflush(stdout); exit(1); }
#define CHECK(cond, what) do { if (!(cond)) die(what); } while (0)

static void *sym(Lib lib, const char *name) {
    void *p = lib_sym(lib, name);
    if (!p) { printf("FAIL missing symbol %s\n", name); exit(1); }
    return p;
}

static Fmu load(const char *path) {
    Fmu f;
    f.lib = lib_open(path);
    if (!f.lib) { printf("FAIL cannot load %s (%s)\n", path, lib_error()); exit(1); }
    f.types_platform = (const char *(*)(void))sym(f.lib, "fmi2GetTypesPlatform");
    f.version = (const char *(*)(void))sym(f.lib, "fmi2GetVersion");
    f.instantiate = (C (*)(const char *, int, const char *, const char *, const Callbacks *, int, int))sym(f.lib, "fmi2Instantiate");
    f.free_instance = (void (*)(C))sym(f.lib, "fmi2FreeInstance");
    f.setup = (St (*)(C, int, double, double, int, double))sym(f.lib, "fmi2SetupExperiment");
    f.enter_init = (St (*)(C))sym(f.lib, "fmi2EnterInitializationMode");
    f.exit_init = (St (*)(C))sym(f.lib, "fmi2ExitInitializationMode");
    f.terminate = (St (*)(C))sym(f.lib, "fmi2Terminate");
    f.set_real = (St (*)(C, const unsigned *, size_t, const double *))sym(f.lib, "fmi2SetReal");
    f.get_real = (St (*)(C, const unsigned *, size_t, double *))sym(f.lib, "fmi2GetReal");
    f.do_step = (St (*)(C, double, double, int))sym(f.lib, "fmi2DoStep");
    return f;
}

#define MAXN 256

/* "a=b,c=d" (sep '=') or "a:b,c:d" (sep ':'); "-" is empty. Returns the count. */
static int parse_pairs(const char *s, char sep, unsigned *left, double *right, int max) {
    int n = 0;
    if (strcmp(s, "-") == 0) return 0;
    const char *p = s;
    while (*p) {
        char *end;
        CHECK(n < max, "too many pairs");
        left[n] = (unsigned)strtoul(p, &end, 10);
        CHECK(*end == sep, "malformed pair list");
        p = end + 1;
        right[n] = strtod(p, &end);
        CHECK(end != p, "malformed pair value");
        n++;
        p = end;
        if (*p == ',') p++;
        else CHECK(*p == '\0', "malformed pair list");
    }
    return n;
}

static int parse_list(const char *s, unsigned *out, int max) {
    int n = 0;
    const char *p = s;
    while (*p) {
        char *end;
        CHECK(n < max, "too many value references");
        out[n++] = (unsigned)strtoul(p, &end, 10);
        CHECK(end != p, "malformed value-reference list");
        p = end;
        if (*p == ',') p++;
        else CHECK(*p == '\0', "malformed value-reference list");
    }
    return n;
}

static C start(const Fmu *f, const char *name, const char *guid, const unsigned *vr, const double *v, int n) {
    /* resource location (a file: URI) of an FMU that needs one, e.g. a Co-Simulation face (tests/test_me_cs_platforms.py) */
    const char *res = getenv(strcmp(name, "plant") == 0 ? "FMI_LOOP_PLANT_RESOURCES" : "FMI_LOOP_CONTROLLER_RESOURCES");
    C c = f->instantiate(name, 1 /* fmi2CoSimulation */, guid, res, &CB, 0, 0);
    CHECK(c, "fmi2Instantiate");
    CHECK(f->setup(c, 0, 0.0, 0.0, 0, 0.0) == 0, "fmi2SetupExperiment");
    CHECK(f->enter_init(c) == 0, "fmi2EnterInitializationMode");
    if (n > 0) CHECK(f->set_real(c, vr, (size_t)n, v) == 0, "fmi2SetReal (start values)");
    CHECK(f->exit_init(c) == 0, "fmi2ExitInitializationMode");
    return c;
}

static void print_value(double v) {
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    printf(" %.17g:%016llx", v, (unsigned long long)bits);
}

int main(int argc, char **argv) {
    if (argc == 4 && strcmp(argv[1], "instantiate") == 0) {
        Fmu f = load(argv[2]);
        C c = f.instantiate("probe", 1, argv[3], NULL, &CB, 0, 1);
        printf("%s\n", c ? "instance" : "null");
        if (c) f.free_instance(c);
        lib_close(f.lib);
        return 0;
    }
    if (argc != 12) {
        fprintf(stderr, "usage: fmi_loop PLANT_LIB PLANT_GUID CTRL_LIB CTRL_GUID STEPS DT PLANT_SET CTRL_SET P2C C2P OUT\n");
        return 2;
    }
    int steps = atoi(argv[5]);
    double dt = strtod(argv[6], NULL);
    static unsigned ps_vr[MAXN], cs_vr[MAXN], p2c_from[MAXN], c2p_from[MAXN], out_vr[MAXN];
    static double ps_v[MAXN], cs_v[MAXN], p2c_to[MAXN], c2p_to[MAXN];
    int n_ps = parse_pairs(argv[7], '=', ps_vr, ps_v, MAXN);
    int n_cs = parse_pairs(argv[8], '=', cs_vr, cs_v, MAXN);
    int n_p2c = parse_pairs(argv[9], ':', p2c_from, p2c_to, MAXN);
    int n_c2p = parse_pairs(argv[10], ':', c2p_from, c2p_to, MAXN);
    int n_out = parse_list(argv[11], out_vr, MAXN);
    static unsigned p2c_dst[MAXN], c2p_dst[MAXN];
    for (int i = 0; i < n_p2c; i++) p2c_dst[i] = (unsigned)p2c_to[i];
    for (int i = 0; i < n_c2p; i++) c2p_dst[i] = (unsigned)c2p_to[i];

    Fmu plant = load(argv[1]);
    Fmu ctrl = load(argv[3]);
    printf("fmi2GetTypesPlatform=%s fmi2GetVersion=%s\n", plant.types_platform(), plant.version());
    C p = start(&plant, "plant", argv[2], ps_vr, ps_v, n_ps);
    C c = start(&ctrl, "controller", argv[4], cs_vr, cs_v, n_cs);

    static double buf[MAXN], out[MAXN];
    double t = 0.0;
    for (int k = 0; k < steps; k++) {
        if (n_p2c > 0) {
            CHECK(plant.get_real(p, p2c_from, (size_t)n_p2c, buf) == 0, "plant fmi2GetReal");
            CHECK(ctrl.set_real(c, p2c_dst, (size_t)n_p2c, buf) == 0, "controller fmi2SetReal");
        }
        CHECK(ctrl.do_step(c, t, dt, 1) == 0, "controller fmi2DoStep");
        if (n_c2p > 0) {
            CHECK(ctrl.get_real(c, c2p_from, (size_t)n_c2p, buf) == 0, "controller fmi2GetReal");
            CHECK(plant.set_real(p, c2p_dst, (size_t)n_c2p, buf) == 0, "plant fmi2SetReal");
        }
        CHECK(plant.do_step(p, t, dt, 1) == 0, "plant fmi2DoStep");
        t = (k + 1) * dt;
        CHECK(plant.get_real(p, out_vr, (size_t)n_out, out) == 0, "plant fmi2GetReal (outputs)");
        printf("%d", k + 1);
        for (int i = 0; i < n_out; i++) print_value(out[i]);
        printf("\n");
    }
    CHECK(plant.terminate(p) == 0 && ctrl.terminate(c) == 0, "fmi2Terminate");
    plant.free_instance(p);
    ctrl.free_instance(c);
    lib_close(ctrl.lib);
    lib_close(plant.lib);
    printf("ok %d steps\n", steps);
    return 0;
}
