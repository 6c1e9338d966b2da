/* A fake of Force Dimension's dhd library, for the tests: the functions the trainer's backend
 * calls, for up to four devices (one by default; the test says how many are connected), each
 * with an end effector the test places (in the device's frame: x towards the user, y right,
 * z up, m) and the forces sent to it recorded, errors injected. The `fake_dhd_*` functions
 * are the test's controls; those without `_of` act on device 0. Built by the test with the
 * system C compiler. */

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

#define DEVICES 4

/* One device's state. */
typedef struct {
    double position_m[3];
    unsigned int buttons;
    double last_force[3];
    int opened, closed, force_enabled;
    /* An error code the next position read fails with (0: none). */
    atomic_int pending_error;
} Device;

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static Device devices[DEVICES];
static int connected = 1;
/* What reached the "motors" of any device: the largest force magnitude sent, and how many
 * non-finite. */
static double largest_force;
static long nonfinite_forces;
static int last_error;
static atomic_long frames;
static int absent, refuse_force;
static double max_force = 9.5;
/* An error code the next dhdSetForce fails with (0: none). */
static atomic_int set_force_error;

/* The device an ID names; device 0 for an ID out of range. */
static Device *device(char id) {
    return (id >= 0 && id < connected) ? &devices[(int)id] : &devices[0];
}

int dhdGetDeviceCount(void) { return absent ? 0 : connected; }

int dhdOpenID(char id) {
    if (absent || id < 0 || id >= connected) { last_error = 3; return -1; }
    devices[(int)id].opened = 1;
    devices[(int)id].closed = 0;
    return id;
}

int dhdOpen(void) { return dhdOpenID(0); }

int dhdClose(char id) { device(id)->closed = 1; return 0; }
int dhdEnableForce(unsigned char on, char id) {
    if (refuse_force) { last_error = 7; return -1; }
    device(id)->force_enabled = on;
    return 0;
}

int dhdGetPosition(double *x, double *y, double *z, char id) {
    Device *d = device(id);
    int error = atomic_exchange(&d->pending_error, 0);
    if (error) { last_error = error; return -1; }
    pthread_mutex_lock(&lock);
    *x = d->position_m[0];
    *y = d->position_m[1];
    *z = d->position_m[2];
    pthread_mutex_unlock(&lock);
    return 0;
}

int dhdGetOrientationFrame(double matrix[3][3], char id) {
    (void)id;
    memset(matrix, 0, 9 * sizeof(double));
    matrix[0][0] = matrix[1][1] = matrix[2][2] = 1.0;
    return 0;
}

unsigned int dhdGetButtonMask(char id) { return device(id)->buttons; }

int dhdSetForce(double fx, double fy, double fz, char id) {
    int error = atomic_exchange(&set_force_error, 0);
    if (error) { last_error = error; atomic_fetch_add(&frames, 1); return -1; }
    Device *d = device(id);
    pthread_mutex_lock(&lock);
    d->last_force[0] = fx;
    d->last_force[1] = fy;
    d->last_force[2] = fz;
    double norm = sqrt(fx * fx + fy * fy + fz * fz);
    if (!isfinite(norm)) nonfinite_forces++;
    else if (norm > largest_force) largest_force = norm;
    pthread_mutex_unlock(&lock);
    atomic_fetch_add(&frames, 1);
    return 0;
}

double dhdGetMaxForce(char id) { (void)id; return max_force; }
const char *dhdGetSystemName(char id) { (void)id; return "fake omega.3"; }
int dhdErrorGetLast(void) { return last_error; }
const char *dhdErrorGetStr(int error) {
    switch (error) {
    case 3: return "no device found";
    case 7: return "communication error";
    default: return "undocumented error";
    }
}
const char *dhdErrorGetLastStr(void) { return dhdErrorGetStr(last_error); }

/* The test's controls. */
void fake_dhd_set_absent(int yes) { absent = yes; }
void fake_dhd_set_connected(int count) { connected = count < DEVICES ? count : DEVICES; }
void fake_dhd_set_effector_of(int id, double x, double y, double z, unsigned int pressed) {
    pthread_mutex_lock(&lock);
    devices[id].position_m[0] = x;
    devices[id].position_m[1] = y;
    devices[id].position_m[2] = z;
    devices[id].buttons = pressed;
    pthread_mutex_unlock(&lock);
}
void fake_dhd_set_effector(double x, double y, double z, unsigned int pressed) {
    fake_dhd_set_effector_of(0, x, y, z, pressed);
}
void fake_dhd_last_force_of(int id, double *out) {
    pthread_mutex_lock(&lock);
    memcpy(out, devices[id].last_force, sizeof devices[id].last_force);
    pthread_mutex_unlock(&lock);
}
void fake_dhd_last_force(double *out) { fake_dhd_last_force_of(0, out); }
void fake_dhd_inject_error_of(int id, int code) { atomic_store(&devices[id].pending_error, code); }
void fake_dhd_inject_error(int code) { fake_dhd_inject_error_of(0, code); }
long fake_dhd_frames(void) { return atomic_load(&frames); }
double fake_dhd_largest_force(void) {
    pthread_mutex_lock(&lock);
    double largest = largest_force;
    pthread_mutex_unlock(&lock);
    return largest;
}
long fake_dhd_nonfinite_forces(void) {
    pthread_mutex_lock(&lock);
    long count = nonfinite_forces;
    pthread_mutex_unlock(&lock);
    return count;
}
int fake_dhd_closed_of(int id) { return devices[id].closed; }
int fake_dhd_closed(void) { return fake_dhd_closed_of(0); }
int fake_dhd_force_enabled(void) { return devices[0].force_enabled; }
void fake_dhd_set_max_force(double newtons) { max_force = newtons; }
void fake_dhd_refuse_force(int yes) { refuse_force = yes; }
void fake_dhd_fail_set_force(int code) { atomic_store(&set_force_error, code); }
