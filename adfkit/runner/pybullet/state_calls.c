/* adfkit's PyBullet state calls in C: many bodies' base states read, and many torques and forces
 * applied, in one call from Python (state_calls.py builds and loads this file).
 *
 * PyBullet has no batched call for separate bodies, so the springs of AMBF's six-dof joints read
 * each free body with getBasePositionAndOrientation and getBaseVelocity and push it with
 * applyExternalTorque / applyExternalForce, ~150 Python calls a physics step. Here the same
 * requests go to the same physics server through PyBullet's own C API (b3RequestActualState...,
 * b3ApplyExternalForce...: the functions pybullet's module is built from, looked up in it), one
 * request a body as PyBullet makes them, so every number is the one the Python calls give.
 *
 * The physics client handle comes from PyBullet's plugin interface: loadPlugin calls
 * initPlugin_adfkit with a client of the world's own server (its plugin manager's), which Python
 * then takes with adfkit_last_client(). Nothing runs inside Bullet's step. */

#include <dlfcn.h>
#include <stddef.h>

/* SharedMemoryPublic.h of the Bullet PyBullet 3.2.7 is built from: a plugin answers it to load */
#define ADFKIT_PYBULLET_MAGIC 202010061
#define ADFKIT_WORLD_FRAME 2 /* EF_WORLD_FRAME */

typedef void *handle;
struct plugin_context { handle client; }; /* b3PluginContext: the client is its first field */

static handle (*request_state)(handle, int);
static handle (*submit)(handle, handle);
static int (*actual_state)(handle, int *, int *, int *, const double **, const double **, const double **,
                           const double **);
static handle (*force_init)(handle);
static void (*add_force)(handle, int, int, const double *, const double *, int);
static void (*add_torque)(handle, int, int, const double *, int);

static handle last_client;

int initPlugin_adfkit(struct plugin_context *context) {
    last_client = context->client;
    return ADFKIT_PYBULLET_MAGIC;
}

void exitPlugin_adfkit(struct plugin_context *context) { (void)context; }

int executePluginCommand_adfkit(struct plugin_context *context, const void *arguments) {
    (void)context;
    (void)arguments;
    return 0;
}

handle adfkit_last_client(void) {
    handle c = last_client;
    last_client = NULL;
    return c;
}

/* Looks PyBullet's C API up in its module (already loaded: its path). 0 when every function is there. */
int adfkit_bind(const char *pybullet_path) {
    void *lib = dlopen(pybullet_path, RTLD_NOW | RTLD_NOLOAD);
    if (lib == NULL) return -1;
    request_state = (handle(*)(handle, int))dlsym(lib, "b3RequestActualStateCommandInit");
    submit = (handle(*)(handle, handle))dlsym(lib, "b3SubmitClientCommandAndWaitStatus");
    actual_state = (int (*)(handle, int *, int *, int *, const double **, const double **, const double **,
                            const double **))dlsym(lib, "b3GetStatusActualState");
    force_init = (handle(*)(handle))dlsym(lib, "b3ApplyExternalForceCommandInit");
    add_force = (void (*)(handle, int, int, const double *, const double *, int))dlsym(lib, "b3ApplyExternalForce");
    add_torque = (void (*)(handle, int, int, const double *, int))dlsym(lib, "b3ApplyExternalTorque");
    return (request_state && submit && actual_state && force_init && add_force && add_torque) ? 0 : -2;
}

/* Each body's base position (3), quaternion (4), linear (3) and angular (3) velocity into out (n x 13),
 * as getBasePositionAndOrientation and getBaseVelocity give them. 0, or -(i+1) where body i failed. */
int adfkit_read_bases(handle client, int n, const int *uids, double *out) {
    for (int i = 0; i < n; i++) {
        const double *q = NULL, *qdot = NULL;
        int nq = 0, nu = 0;
        handle status = submit(client, request_state(client, uids[i]));
        if (!actual_state(status, NULL, &nq, &nu, NULL, &q, &qdot, NULL) || nq < 7 || nu < 6) return -(i + 1);
        double *row = out + 13 * i;
        for (int k = 0; k < 7; k++) row[k] = q[k];
        for (int k = 0; k < 6; k++) row[7 + k] = qdot[k];
    }
    return 0;
}

/* applyExternalTorque(uids[i], links[i], torques[i], WORLD_FRAME) for each i, one command each as
 * PyBullet's; then, where forces is not NULL, applyExternalForce(fuids[j], flinks[j], forces[j],
 * at[j], WORLD_FRAME) for each j < m. */
void adfkit_apply(handle client, int n, const int *uids, const int *links, const double *torques, int m,
                  const int *fuids, const int *flinks, const double *forces, const double *at) {
    for (int i = 0; i < n; i++) {
        handle cmd = force_init(client);
        add_torque(cmd, uids[i], links[i], torques + 3 * i, ADFKIT_WORLD_FRAME);
        submit(client, cmd);
    }
    if (forces == NULL) return;
    for (int j = 0; j < m; j++) {
        handle cmd = force_init(client);
        add_force(cmd, fuids[j], flinks[j], forces + 3 * j, at + 3 * j, ADFKIT_WORLD_FRAME);
        submit(client, cmd);
    }
}
