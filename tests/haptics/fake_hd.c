/* A fake of the OpenHaptics HD library, for the tests: the functions the trainer's backend
 * calls, for up to four devices (each initialization is the next one), with one scheduler
 * thread that runs every scheduled callback every millisecond, a stylus per device the test
 * places, and a record of the forces the callbacks render. The `fake_hd_*` functions
 * are the test's controls. Built by the test with the system C compiler. */

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef unsigned int HHD;
typedef unsigned int (*Callback)(void *);
typedef struct {
    unsigned int code;
    int internal;
    unsigned int handle;
} ErrorInfo;

#define DEVICES 4
#define CALLBACKS 4

/* One device's state; handles are 1 to DEVICES, in the order the devices are initialized. */
typedef struct {
    double position_mm[3];
    int buttons;
    double last_force[3];
    int disabled;
    atomic_uint pending_error;
} Device;

static Device devices[DEVICES + 1];
static int initialized;
/* Each thread's current device (as HD keeps it): made current, or the frame it is in. */
static __thread HHD current = 1;
/* What reached the "motors" of any device: the largest force magnitude rendered, and how
 * many non-finite. */
static double largest_force;
static long nonfinite_forces;
static atomic_long frames;
static atomic_int running;
static int force_output;
static int in_frame;
static pthread_t scheduler;
/* The scheduled callbacks; a handle is its slot plus 7. */
static struct {
    Callback callback;
    void *data;
} callbacks[CALLBACKS];
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static unsigned int init_error;

static double nominal_max_force = 3.0;
static double nominal_continuous_force = 0.75;

static Device *device(HHD handle) {
    return (handle >= 1 && handle <= DEVICES) ? &devices[handle] : &devices[1];
}

HHD hdInitDevice(const char *name) {
    if (name && strcmp(name, "absent") == 0) {
        init_error = 0x0303;
        return 0xFFFFFFFF;
    }
    if (initialized >= DEVICES) {
        init_error = 0x0301;
        return 0xFFFFFFFF;
    }
    HHD handle = ++initialized;
    devices[handle].disabled = 0;
    current = handle;
    /* A device that opens but reports an error with its handle: it must still be released. */
    if (name && strcmp(name, "half-open") == 0) init_error = 0x0301;
    return handle;
}

void hdDisableDevice(HHD handle) { device(handle)->disabled = 1; }
void hdMakeCurrentDevice(HHD handle) { current = handle; }

ErrorInfo hdGetError(void) {
    ErrorInfo info = {0, 0, current};
    if (init_error) {
        info.code = init_error;
        init_error = 0;
        return info;
    }
    info.code = atomic_exchange(&device(current)->pending_error, 0);
    info.internal = info.code ? 42 : 0;
    return info;
}

void hdEnable(unsigned int capability) {
    if (capability == 0x4000) force_output = 1;
}

void hdBeginFrame(HHD handle) { pthread_mutex_lock(&lock); current = handle; in_frame = 1; }
void hdEndFrame(HHD handle) { (void)handle; in_frame = 0; pthread_mutex_unlock(&lock); }

void hdGetDoublev(unsigned int parameter, double *values) {
    Device *d = device(current);
    switch (parameter) {
    case 0x2050: memcpy(values, d->position_mm, sizeof d->position_mm); break;
    case 0x2052: /* identity transform, column-major, translation last */
        memset(values, 0, 16 * sizeof(double));
        values[0] = values[5] = values[10] = values[15] = 1.0;
        memcpy(values + 12, d->position_mm, sizeof d->position_mm);
        break;
    case 0x2551: {
        double box[6] = {-80, -60, -35, 80, 60, 35};
        memcpy(values, box, sizeof box);
        break;
    }
    case 0x2603: values[0] = nominal_max_force; break;
    case 0x2604: values[0] = nominal_continuous_force; break;
    default: break;
    }
}

void hdGetIntegerv(unsigned int parameter, int *values) {
    if (parameter == 0x2000) values[0] = device(current)->buttons;
}

const char *hdGetString(unsigned int parameter) {
    return parameter == 0x2501 ? "Fake Touch" : 0;
}

void hdSetDoublev(unsigned int parameter, const double *values) {
    if (parameter != 0x2700 || !in_frame) return;
    memcpy(device(current)->last_force, values, 3 * sizeof(double));
    double norm = sqrt(values[0] * values[0] + values[1] * values[1] + values[2] * values[2]);
    if (!isfinite(norm)) nonfinite_forces++;
    else if (norm > largest_force) largest_force = norm;
}

/* Runs every scheduled callback each millisecond; one that returns 0 (HD_CALLBACK_DONE) is
 * unscheduled. */
static void *run_scheduler(void *unused) {
    (void)unused;
    struct timespec tick = {0, 1000000};
    while (atomic_load(&running)) {
        for (int k = 0; k < CALLBACKS; k++) {
            Callback callback = __atomic_load_n(&callbacks[k].callback, __ATOMIC_ACQUIRE);
            if (callback && callback(callbacks[k].data) == 0)
                __atomic_store_n(&callbacks[k].callback, (Callback)0, __ATOMIC_RELEASE);
        }
        atomic_fetch_add(&frames, 1);
        nanosleep(&tick, 0);
    }
    return 0;
}

unsigned long hdScheduleAsynchronous(Callback cb, void *data, unsigned short priority) {
    (void)priority;
    for (int k = 0; k < CALLBACKS; k++) {
        if (!__atomic_load_n(&callbacks[k].callback, __ATOMIC_ACQUIRE)) {
            callbacks[k].data = data;
            __atomic_store_n(&callbacks[k].callback, cb, __ATOMIC_RELEASE);
            return 7 + k;
        }
    }
    return 0;
}

/* Started once: a second start while it runs changes nothing. */
void hdStartScheduler(void) {
    if (atomic_exchange(&running, 1)) return;
    pthread_create(&scheduler, 0, run_scheduler, 0);
    /* For a test running the trainer itself: a file `<FAKE_HD_REPORT>.started` says the servo
     * runs. */
    const char *report = getenv("FAKE_HD_REPORT");
    if (report) {
        char started[4096];
        snprintf(started, sizeof started, "%s.started", report);
        FILE *file = fopen(started, "w");
        if (file) fclose(file);
    }
}

void hdStopScheduler(void) {
    if (atomic_exchange(&running, 0)) pthread_join(scheduler, 0);
}

void hdUnschedule(unsigned long handle) {
    if (handle >= 7 && handle < 7 + CALLBACKS)
        __atomic_store_n(&callbacks[handle - 7].callback, (Callback)0, __ATOMIC_RELEASE);
}

/* The test's controls; those without `_of` act on the first device (handle 1). */
void fake_hd_set_stylus_of(HHD handle, double x_mm, double y_mm, double z_mm, int pressed) {
    pthread_mutex_lock(&lock);
    Device *d = device(handle);
    d->position_mm[0] = x_mm;
    d->position_mm[1] = y_mm;
    d->position_mm[2] = z_mm;
    d->buttons = pressed;
    pthread_mutex_unlock(&lock);
}
void fake_hd_set_stylus(double x_mm, double y_mm, double z_mm, int pressed) {
    fake_hd_set_stylus_of(1, x_mm, y_mm, z_mm, pressed);
}

void fake_hd_last_force_of(HHD handle, double *out) {
    pthread_mutex_lock(&lock);
    memcpy(out, device(handle)->last_force, 3 * sizeof(double));
    pthread_mutex_unlock(&lock);
}
void fake_hd_last_force(double *out) { fake_hd_last_force_of(1, out); }

void fake_hd_inject_error_of(HHD handle, unsigned int code) {
    atomic_store(&device(handle)->pending_error, code);
}
void fake_hd_inject_error(unsigned int code) { fake_hd_inject_error_of(1, code); }
long fake_hd_frames(void) { return atomic_load(&frames); }
double fake_hd_largest_force(void) {
    pthread_mutex_lock(&lock);
    double largest = largest_force;
    pthread_mutex_unlock(&lock);
    return largest;
}
long fake_hd_nonfinite_forces(void) {
    pthread_mutex_lock(&lock);
    long count = nonfinite_forces;
    pthread_mutex_unlock(&lock);
    return count;
}
int fake_hd_running(void) { return atomic_load(&running); }
int fake_hd_disabled_of(HHD handle) { return device(handle)->disabled; }
int fake_hd_disabled(void) { return fake_hd_disabled_of(1); }
int fake_hd_force_output(void) { return force_output; }
/* How many callbacks are scheduled. */
int fake_hd_scheduled(void) {
    int count = 0;
    for (int k = 0; k < CALLBACKS; k++)
        count += __atomic_load_n(&callbacks[k].callback, __ATOMIC_ACQUIRE) != 0;
    return count;
}
/* The peak force the device reports (HD_NOMINAL_MAX_FORCE), for the next device opened. */
void fake_hd_set_nominal_max_force(double newtons) { nominal_max_force = newtons; }

/* For a test running the trainer itself, which cannot call the controls: the stylus placed
 * from `FAKE_HD_STYLUS` ("x,y,z" in mm) when the library loads, and what the device was left
 * in written to the file `FAKE_HD_REPORT` names when the process lets the library go. */
__attribute__((constructor)) static void place_stylus_from_environment(void) {
    const char *stylus = getenv("FAKE_HD_STYLUS");
    double *mm = devices[1].position_mm;
    if (stylus) sscanf(stylus, "%lf,%lf,%lf", &mm[0], &mm[1], &mm[2]);
}

__attribute__((destructor)) static void report_to_environment(void) {
    const char *report = getenv("FAKE_HD_REPORT");
    FILE *file = report ? fopen(report, "w") : 0;
    if (!file) return;
    fprintf(file, "{\"last_force\": [%g, %g, %g], \"largest_force\": %g, \"frames\": %ld, "
                  "\"running\": %d, \"disabled\": %d}\n",
            devices[1].last_force[0], devices[1].last_force[1], devices[1].last_force[2],
            largest_force, atomic_load(&frames), atomic_load(&running), devices[1].disabled);
    fclose(file);
}
