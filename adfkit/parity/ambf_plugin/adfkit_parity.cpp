// adfkit's AMBF simulator plugin (`ambf_simulator --plugins libadfkit_parity.so`): it writes
// what AMBF created from the scene (rigid and soft bodies, ghosts, joints, sensors, actuators),
// then every rigid body's pose and every joint's position as the scene plays, and drives the
// scene from a command file (joint position, velocity and effort commands, grasp and release
// with AMBF's own constraint actuators). adfkit parity reads what it writes.
//
// Configuration (environment):
//   ADFKIT_PARITY_OUT       file to write, JSON lines (required)
//   ADFKIT_PARITY_SECONDS   simulated seconds to play; 0 writes what was created and exits (default 0)
//   ADFKIT_PARITY_EVERY     a sample every so many simulated seconds (0: first and last only)
//   ADFKIT_PARITY_GHOSTS    "follow" (default): every object's global pose is brought up to date after
//                           each physics step, so that ghost objects follow their parents as they do
//                           with AMBF's window open (its graphics loop updates them, ~120 times a
//                           second; headless nothing does and every ghost stays where it was made);
//                           "headless": left as AMBF leaves them without a window
//   ADFKIT_PARITY_COMMANDS  command file: one command a line, "TIME KIND TARGET [ARG]", KIND one of
//                           position|velocity|effort (TARGET a joint's qualified name, ARG the value),
//                           grasp (TARGET an actuator, ARG a rigid body [x y z qx qy qz qw]: where the
//                           body lies, or, given its frame in the actuator's parent's frame, held
//                           there: afConstraintActuator::actuate with that offset), release (TARGET an actuator),
//                           place (TARGET a rigid body, ARG its body frame "x y z qx qy qz qw": set
//                           there at rest), force (TARGET a rigid body, ARG "fx fy fz px py pz": a
//                           force at a world point, every step until its next force command);
//                           pose (TARGET a dynamic rigid body, ARG "x y z qx qy qz qw": every step
//                           until its next pose command, what AMBF's ROS plugin does with a
//                           RigidBodyCmd TYPE_POSITION for a dynamic body, ObjectCommPlugin's
//                           rigidBodyFetchCommand: the body's Cartesian controller's output for
//                           its COM position and rotation with the step's dt, set as its velocity,
//                           or applied as a force and torque if the controller outputs a force);
//                           collide (TARGET a rigid body, ARG "BODY 0|1": 0 lets the two pass through each
//                           other, as a task's set_collision does; 1 undoes that),
//                           follow (TARGET a revolute or prismatic joint, ARG a position: a point
//                           of a path the joint is to follow; a joint's follow points, taken in
//                           time order, make its path, linear between points, held at its last),
//                           a joint command holds until the joint's next command. From its first
//                           follow point on, a joint is driven as a client servoing the measured
//                           joint does: each physics step a velocity command of the path's slope
//                           plus FOLLOW_GAIN times the path's position less the measured one (its
//                           position, velocity and effort commands are then left unplayed)
//   ADFKIT_PARITY_FOLLOW_GAIN  the follow's feedback gain, 1/s (default 100)
//   ADFKIT_PARITY_PACE      "RAD M WAIT_S" (default off): a paced replay, as a client that sends a
//                           set-point and waits for the measured joints. The command file is read on
//                           a command clock that advances one physics step only while every joint
//                           under a position command stands within RAD (a revolute joint) or M (a
//                           prismatic one) of its set-point; physics runs all the while. A joint still
//                           outside after WAIT_S of simulated time held the clock (a jaw closed on a
//                           needle) is let go of until it comes within its tolerance again, and each
//                           such give-up is counted. SECONDS and EVERY are then command-clock time
//   ADFKIT_PARITY_PACE_MAX  a paced replay ends at this simulated time if its clock has not reached
//                           SECONDS by then (default 20 x SECONDS)
//   ADFKIT_PARITY_CONTACTS  "1": each sample also lists the contact manifolds of the last physics step
//                           that hold points, [A, B, points, least distance, summed normal impulse]
//                           (A and B: a rigid body's or ghost's qualified name, "?" for anything else)
//   ADFKIT_PARITY_VELOCITIES "1": each sample also lists every rigid body's linear velocity (m/s, the
//                           created record's order), as Bullet holds it after AMBF's ghosts acted
//   ADFKIT_PARITY_POINTS    "T0 T1 A B[,B...]" with ADFKIT_PARITY_POINTS_OUT (a file): every physics step
//                           from T0 to T1 simulated seconds, each contact point between a rigid body whose
//                           qualified name holds A and one whose name holds one of the Bs, one JSON line a
//                           manifold: {"t","A","B","breaking":the manifold's contact breaking threshold,
//                           "rotA","rotB":each body's centre-of-mass frame (quaternion xyzw), "posA","posB",
//                           "points":[[index0, index1 (the compound's child shapes), world point on A, on B,
//                           local point on A, on B (centre-of-mass frames), normal on B, distance, normal
//                           impulse, lifetime], ...]}; first a {"kind":"shapes"} line: those bodies' collision
//                           shapes as Bullet holds them (type, margin, a capsule's radius, half height and
//                           axis, a compound's children and their frames) and the world's collision settings
////   Measurement knobs, which change what AMBF does (for finding out what a behaviour comes from):
//   ADFKIT_PARITY_STILL_STATIC "1": every static body (mass 0) is put back at rest after each step
//                           (AMBF's ghosts set the velocity of every body they sense, a static one too)
//   ADFKIT_PARITY_JOINT_ITERATIONS "SUBSTRING N": the joints whose qualified names hold SUBSTRING solved
//                           with N iterations of their own, the rest with the world's
//   ADFKIT_PARITY_FRICTION  "two" (two friction directions per contact point, PyBullet's world's), "fresh"
//                           (every friction row started from zero, PyBullet's Bullet's), "two fresh": both
//   ADFKIT_PARITY_UNGHOST   "SUBSTRING PARTS": the rigid bodies whose qualified names hold SUBSTRING get
//                           back, after each step, what AMBF's ghosts changed of them: PARTS names any of
//                           linear and angular (the velocities Bullet's step left, read at its internal
//                           tick callback) and gravity (the world's)
//   ADFKIT_PARITY_GRASP_ROWS "ERP CFM N": each grasp's btFixedConstraint (AMBF's constraint actuator) gets
//                           ERP and CFM on its six locked rows (AMBF leaves the world's, 0.2 and 0) and, N > 0,
//                           N solver iterations of its own
//   ADFKIT_PARITY_FINE      "T0 T1 [T0 T1 ...]": a sample every physics step from T0 to T1 (simulated s),
//                           besides ADFKIT_PARITY_EVERY's (it changes nothing AMBF does)
//
// Records: {"kind":"created",...} once, {"kind":"sample",...} per sample (its "clock": the command
// clock, the simulated time "t" when unpaced), {"kind":"end",...} last (a paced replay's "pace":
// steps the clock was held, give-ups, the joints given up on),
// or {"kind":"error","message":...} (and exit status 3) for a command file it cannot follow.
// The process ends (_exit) once the last sample is written: the simulator has no other way out
// when it runs headless.
#include <afFramework.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

using namespace ambf;
using namespace chai3d;
using namespace std;

namespace {

string json_text(const string& s) {
    string out = "\"";
    for (unsigned char c : s) {
        if (c == '"' || c == '\\') { out += '\\'; out += (char)c; }
        else if (c < 0x20) { char buf[8]; snprintf(buf, sizeof buf, "\\u%04x", c); out += buf; }
        else out += (char)c;
    }
    return out + "\"";
}

string num(double v) {
    if (!(v == v) || v > 1e300 || v < -1e300) return "null";  // strict JSON: no NaN or Inf
    char buf[40];
    snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

string vec(const btVector3& v) { return "[" + num(v.x()) + "," + num(v.y()) + "," + num(v.z()) + "]"; }

const char* joint_type(afJointType t) {
    switch (t) {
    case afJointType::REVOLUTE: return "revolute";
    case afJointType::PRISMATIC: return "prismatic";
    case afJointType::LINEAR_SPRING: return "linear spring";
    case afJointType::TORSION_SPRING: return "torsion spring";
    case afJointType::P2P: return "p2p";
    case afJointType::FIXED: return "fixed";
    case afJointType::CONE_TWIST: return "cone twist";
    case afJointType::SIX_DOF: return "six dof";
    case afJointType::SIX_DOF_SPRING: return "six dof spring";
    default: return "invalid";
    }
}

const char* sensor_type(afSensorType t) {
    switch (t) {
    case afSensorType::RAYTRACER: return "proximity";
    case afSensorType::RANGE: return "range";
    case afSensorType::RESISTANCE: return "resistance";
    default: return "invalid";
    }
}

struct Command {
    double t;
    string kind, target, arg;
    double value;
    vector<double> numbers;  // a place's pose, a force's vector and point
    int line;
};

// a revolute or prismatic joint driven to a position: its limits, and how far it stands from a
// position (clamped to the limits, as commandPosition clamps a set-point; a revolute joint without
// limits the shortest angle)
struct Driven {
    afJointPtr joint = nullptr;
    bool revolute = true, limited = false;
    double lo = 0.0, hi = 0.0;

    void take(afJointPtr j) {
        joint = j;
        revolute = j->m_jointType == afJointType::REVOLUTE;
        afJointAttributes* a = dynamic_cast<afJointAttributes*>(j->getAttributes());
        limited = a && a->m_enableLimits;
        lo = j->getLowerLimit();
        hi = j->getUpperLimit();
    }

    double error(double target) const {
        if (limited) target = max(lo, min(hi, target));
        double now = joint->getPosition();
        return revolute && !limited ? joint->getShortestAngle(now, target) : target - now;
    }
};

// a joint's path to follow: points (t, position) in time order, the segment now played
struct Path : Driven {
    vector<pair<double, double>> points;
    size_t at = 0;
    double worst = 0.0, sum = 0.0;  // the tracking error (|path - measured|) before each command
    long n = 0;
};

// a joint under a position command, as the paced clock waits on it
struct Drive : Driven {
    double heldSince = -1.0;  // simulated time it began holding the clock (-1: it is not)
    bool excused = false;     // given up on until it comes within its tolerance again
};

}  // namespace

class AdfkitParity : public afSimulatorPlugin {
public:
    virtual int init(int argc, char** argv, const afWorldPtr a_afWorld) {
        m_world = a_afWorld;
        const char* out = getenv("ADFKIT_PARITY_OUT");
        m_out = out ? fopen(out, "w") : nullptr;
        if (!m_out) {
            fprintf(stderr, "adfkit_parity: ADFKIT_PARITY_OUT is not a file it can write\n");
            _exit(3);
        }
        m_seconds = env_double("ADFKIT_PARITY_SECONDS", 0.0);
        m_followGain = env_double("ADFKIT_PARITY_FOLLOW_GAIN", 100.0);
        if (!(m_followGain > 0)) fail("ADFKIT_PARITY_FOLLOW_GAIN: expected a positive number");
        m_every = env_double("ADFKIT_PARITY_EVERY", 0.0);
        const char* contacts = getenv("ADFKIT_PARITY_CONTACTS");
        m_contacts = contacts && string(contacts) == "1";
        const char* ghosts = getenv("ADFKIT_PARITY_GHOSTS");
        m_followGhosts = !(ghosts && string(ghosts) == "headless");
        const char* velocities = getenv("ADFKIT_PARITY_VELOCITIES");
        m_velocities = velocities && string(velocities) == "1";
        const char* still = getenv("ADFKIT_PARITY_STILL_STATIC");
        m_stillStatic = still && string(still) == "1";
        // a measurement's knob: "SUBSTRING PARTS" undoes what AMBF's ghosts did after each step to
        // the rigid bodies whose qualified names hold SUBSTRING, PARTS of linear, angular, gravity
        const char* unghost = getenv("ADFKIT_PARITY_UNGHOST");
        if (unghost && *unghost) {
            istringstream us(unghost);
            string parts;
            us >> m_unghostName >> parts;
            m_unghostLinear = parts.find("linear") != string::npos;
            m_unghostAngular = parts.find("angular") != string::npos;
            m_unghostGravity = parts.find("gravity") != string::npos;
            for (afRigidBodyPtr rb : m_world->getRigidBodies())
                if (rb->getQualifiedName().find(m_unghostName) != string::npos) m_unghosted.push_back(rb->m_bulletRigidBody);
            m_unghostBefore.resize(m_unghosted.size() * 2);
            m_world->m_bulletWorld->setInternalTickCallback(&AdfkitParity::after_tick, this, false);
        }
        const char* points = getenv("ADFKIT_PARITY_POINTS");
        if (points && *points) {
            istringstream qs(points);
            string bs;
            if (!(qs >> m_pointsFrom >> m_pointsTo >> m_pointsA >> bs)) fail("ADFKIT_PARITY_POINTS: expected \"T0 T1 A B[,B...]\"");
            istringstream bss(bs);
            for (string b; getline(bss, b, ',');)
                if (!b.empty()) m_pointsB.push_back(b);
            const char* pout = getenv("ADFKIT_PARITY_POINTS_OUT");
            m_pointsOut = pout ? fopen(pout, "w") : nullptr;
            if (!m_pointsOut) fail("ADFKIT_PARITY_POINTS_OUT is not a file it can write");
            write_shapes();
        }
        // a measurement's knob: Bullet's solver iterations (AMBF leaves them at Bullet's 10)
        int iterations = (int)env_double("ADFKIT_PARITY_SOLVER_ITERATIONS", 0.0);
        if (iterations > 0) m_world->m_bulletWorld->getSolverInfo().m_numIterations = iterations;
        // a measurement's knob: how contacts' friction is solved; "two": two friction directions per
        // contact point (PyBullet's world; AMBF's solves one), "fresh": every friction row started from
        // zero (PyBullet's Bullet; AMBF's from 0.85 of its last impulse), "two fresh": both
        // a measurement's knob: "SUBSTRING N" solves the joints whose qualified names hold SUBSTRING
        // with N iterations of their own (btTypedConstraint::setOverrideNumSolverIterations), the
        // rest of the world with the world's
        const char* jointIterations = getenv("ADFKIT_PARITY_JOINT_ITERATIONS");
        if (jointIterations && *jointIterations) {
            istringstream js(jointIterations);
            string name;
            int n = 0;
            if (!(js >> name >> n) || n <= 0) fail("ADFKIT_PARITY_JOINT_ITERATIONS: expected \"SUBSTRING N\", N > 0");
            for (afJointPtr j : m_world->getJoints())
                if (j->getQualifiedName().find(name) != string::npos && j->getConstraint())
                    j->getConstraint()->setOverrideNumSolverIterations(n);
        }
        const char* graspRows = getenv("ADFKIT_PARITY_GRASP_ROWS");
        if (graspRows && *graspRows) {
            istringstream gs(graspRows);
            if (!(gs >> m_graspErp >> m_graspCfm >> m_graspIterations) || m_graspErp < 0 || m_graspCfm < 0)
                fail("ADFKIT_PARITY_GRASP_ROWS: expected \"ERP CFM N\"");
            m_graspRows = true;
        }
        const char* fine = getenv("ADFKIT_PARITY_FINE");
        if (fine && *fine) {
            istringstream fs(fine);
            double a, b;
            while (fs >> a >> b) m_fine.push_back(make_pair(a, b));
        }
        const char* friction = getenv("ADFKIT_PARITY_FRICTION");
        if (friction && *friction) {
            string f(friction);
            if (f.find("two") != string::npos)
                m_world->m_bulletWorld->getSolverInfo().m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
            if (f.find("fresh") != string::npos)
                m_world->m_bulletWorld->setInternalTickCallback(&AdfkitParity::before_tick, this, true);
        }
        const char* pace = getenv("ADFKIT_PARITY_PACE");
        if (pace && *pace) {
            istringstream ps(pace);
            if (!(ps >> m_paceRad >> m_paceM >> m_paceWait) || m_paceRad <= 0 || m_paceM <= 0 || m_paceWait <= 0)
                fail("ADFKIT_PARITY_PACE: expected three positive numbers, RAD M WAIT_S");
            m_paced = true;
            m_paceMax = env_double("ADFKIT_PARITY_PACE_MAX", 20.0 * m_seconds);
        }
        update_global_poses();
        write_created();
        const char* cmds = getenv("ADFKIT_PARITY_COMMANDS");
        if (cmds && *cmds) read_commands(cmds);
        sample(0);
        m_nextSample = m_every > 0 ? m_every : m_seconds;
        if (m_seconds <= 0) finish(0);
        activate(0.0);
        m_clock = chrono::steady_clock::now();
        return 1;
    }

    virtual void physicsUpdate(double dt) {
        m_steps++;
        if (m_stillStatic) still_static();
        if (!m_unghosted.empty()) unghost();
        update_global_poses();
        double t = m_world->getSimulationTime();
        if (!m_paced) m_cmdClock = t;
        else if (joints_arrived(t)) m_cmdClock += dt;
        else m_heldSteps++;
        if (m_pointsOut && t + 1e-9 >= m_pointsFrom && t <= m_pointsTo + 1e-9) write_points(t);
        activate(m_cmdClock);
        drive(dt);
        double c = m_cmdClock;
        bool last = c + 1e-9 >= m_seconds || (m_paced && t + 1e-9 >= m_paceMax);
        bool fine = false;
        for (auto& w : m_fine) fine = fine || (c + 1e-9 >= w.first && c <= w.second + 1e-9);
        if (last || fine || c + 1e-9 >= m_nextSample) {
            sample(m_steps);
            while (m_nextSample <= c + 1e-9) m_nextSample += m_every > 0 ? m_every : m_seconds;
        }
        if (last) finish(m_steps);
    }

    virtual void reset() {}
    virtual bool close() { return 0; }

private:
    // Bullet's step ended (before AMBF's ghosts act): the velocities the ghosts will change
    // before each physics step: the friction impulses the contact points kept from the last step
    // forgotten, so that the solver starts every friction row from zero
    static void before_tick(btDynamicsWorld* w, btScalar) {
        btDispatcher* d = w->getDispatcher();
        for (int i = 0; i < d->getNumManifolds(); i++) {
            btPersistentManifold* m = d->getManifoldByIndexInternal(i);
            for (int k = 0; k < m->getNumContacts(); k++) {
                btManifoldPoint& p = m->getContactPoint(k);
                p.m_appliedImpulseLateral1 = 0;
                p.m_appliedImpulseLateral2 = 0;
            }
        }
    }

    static void after_tick(btDynamicsWorld* w, btScalar) {
        AdfkitParity* self = static_cast<AdfkitParity*>(w->getWorldUserInfo());
        for (size_t i = 0; i < self->m_unghosted.size(); i++) {
            self->m_unghostBefore[2 * i] = self->m_unghosted[i]->getLinearVelocity();
            self->m_unghostBefore[2 * i + 1] = self->m_unghosted[i]->getAngularVelocity();
        }
    }

    void unghost() {
        btVector3 g = m_world->m_bulletWorld->getGravity();
        for (size_t i = 0; i < m_unghosted.size(); i++) {
            btRigidBody* b = m_unghosted[i];
            if (m_unghostLinear) b->setLinearVelocity(m_unghostBefore[2 * i]);
            if (m_unghostAngular) b->setAngularVelocity(m_unghostBefore[2 * i + 1]);
            if (m_unghostGravity) b->setGravity(g);
        }
    }

    // a static body (mass 0) at rest again after AMBF's ghosts set its velocity: a measurement's knob
    void still_static() {
        for (afRigidBodyPtr rb : m_world->getRigidBodies()) {
            btRigidBody* b = rb->m_bulletRigidBody;
            if (!b->isStaticObject()) continue;
            b->setLinearVelocity(btVector3(0, 0, 0));
            b->setAngularVelocity(btVector3(0, 0, 0));
        }
    }

    // what AMBF's graphics loop does (afWorld::updateSceneObjects) for the poses physics reads:
    // a ghost object places itself at its global pose at each step
    void update_global_poses() {
        if (!m_followGhosts) return;
        for (afModelPtr m : m_world->getModels()) m->updateGlobalPose();
    }

    // the paced clock's rule: every joint under a position command within its tolerance of its
    // set-point (clamped to its limits, as commandPosition clamps it), or given up on after the
    // bounded wait
    bool joints_arrived(double t) {
        bool all = true;
        for (auto& kv : m_positionDrives) {
            Drive& d = kv.second;
            double err = d.error(m_drives[kv.first].value);
            bool within = fabs(err) <= (d.revolute ? m_paceRad : m_paceM);
            if (within) {
                d.excused = false;
                d.heldSince = -1.0;
                continue;
            }
            if (d.excused) continue;
            if (d.heldSince < 0) d.heldSince = t;
            if (t - d.heldSince + 1e-9 >= m_paceWait) {
                d.excused = true;
                m_giveUps++;
                m_givenUp[kv.first]++;
                continue;
            }
            all = false;
        }
        return all;
    }

    static double env_double(const char* name, double fallback) {
        const char* v = getenv(name);
        return v && *v ? atof(v) : fallback;
    }

    void fail(const string& message) {
        fprintf(m_out, "{\"kind\":\"error\",\"message\":%s}\n", json_text(message).c_str());
        fflush(m_out);
        _exit(3);
    }

    void finish(long steps) {
        double wall = chrono::duration<double>(chrono::steady_clock::now() - m_clock).count();
        string pace = "null";
        if (m_paced) {
            pace = "{\"held_steps\":" + to_string(m_heldSteps) + ",\"give_ups\":" + to_string(m_giveUps) +
                   ",\"clock_reached\":" + (m_cmdClock + 1e-9 >= m_seconds ? "true" : "false") + ",\"given_up_on\":{";
            bool first = true;
            for (auto& kv : m_givenUp) {
                pace += (first ? "" : ",") + json_text(kv.first) + ":" + to_string(kv.second);
                first = false;
            }
            pace += "}}";
        }
        string follow = "{";
        bool firstPath = true;
        for (auto& kv : m_paths) {
            const Path& p = kv.second;
            follow += (firstPath ? "" : ",") + json_text(kv.first) + ":{\"steps\":" + to_string(p.n) +
                      ",\"max_error\":" + num(p.worst) + ",\"mean_error\":" + num(p.n ? p.sum / p.n : 0.0) + "}";
            firstPath = false;
        }
        follow += "}";
        fprintf(m_out, "{\"kind\":\"end\",\"steps\":%ld,\"t\":%s,\"clock\":%s,\"wall_s\":%s,\"pace\":%s,\"follow\":%s}\n",
                steps, num(m_world->getSimulationTime()).c_str(), num(m_paced ? m_cmdClock : m_world->getSimulationTime()).c_str(),
                num(steps ? wall : 0.0).c_str(), pace.c_str(), follow.c_str());
        fflush(m_out);
        fclose(m_out);
        if (m_pointsOut) fclose(m_pointsOut);
        _exit(0);
    }

    static string body_name(afRigidBodyPtr rb) { return rb ? json_text(rb->getQualifiedName()) : "null"; }

    void write_created() {
        string s = "{\"kind\":\"created\",\"bodies\":[";
        bool first = true;
        for (afRigidBodyPtr rb : m_world->getRigidBodies()) {
            s += (first ? "" : ",") + string("{\"name\":") + json_text(rb->getName()) +
                 ",\"qname\":" + json_text(rb->getQualifiedName()) + ",\"mass\":" + num(rb->getMass()) +
                 ",\"inertia\":" + vec(rb->m_bulletRigidBody->getLocalInertia()) + "}";
            first = false;
        }
        s += "],\"soft_bodies\":[";
        first = true;
        for (afSoftBodyPtr sb : m_world->getSoftBodies()) {
            s += (first ? "" : ",") + string("{\"name\":") + json_text(sb->getName()) +
                 ",\"qname\":" + json_text(sb->getQualifiedName()) + "}";
            first = false;
        }
        s += "],\"ghosts\":[";
        first = true;
        for (afGhostObjectPtr g : m_world->getGhostObjects()) {
            afRigidBodyPtr parent = dynamic_cast<afRigidBodyPtr>(g->getParentObject());
            s += (first ? "" : ",") + string("{\"name\":") + json_text(g->getName()) +
                 ",\"qname\":" + json_text(g->getQualifiedName()) + ",\"parent\":" + body_name(parent) + "}";
            first = false;
        }
        s += "],\"joints\":[";
        first = true;
        for (afJointPtr j : m_world->getJoints()) {
            afJointAttributes* a = dynamic_cast<afJointAttributes*>(j->getAttributes());
            btTypedConstraint* c = j->getConstraint();
            afRigidBodyPtr parent = c ? m_world->getRigidBody(&c->getRigidBodyA(), true) : nullptr;
            afRigidBodyPtr child = c ? m_world->getRigidBody(&c->getRigidBodyB(), true) : nullptr;
            s += (first ? "" : ",") + string("{\"name\":") + json_text(j->getName()) +
                 ",\"qname\":" + json_text(j->getQualifiedName()) + ",\"type\":\"" + joint_type(j->m_jointType) +
                 "\",\"parent\":" + body_name(parent) + ",\"child\":" + body_name(child);
            if (a) {
                s += ",\"motor\":" + string(a->m_enableMotor ? "true" : "false") +
                     ",\"limits\":" + (a->m_enableLimits ? "[" + num(a->m_lowerLimit) + "," + num(a->m_upperLimit) + "]" : "null") +
                     ",\"max_motor_impulse\":" + num(a->m_maxMotorImpulse) +
                     ",\"controller\":{\"P\":" + num(a->m_controllerAttribs.m_P) + ",\"I\":" + num(a->m_controllerAttribs.m_I) +
                     ",\"D\":" + num(a->m_controllerAttribs.m_D) + ",\"output\":\"" +
                     (a->m_controllerAttribs.m_outputType == afControlType::FORCE ? "force" : "velocity") + "\"}";
            }
            s += "}";
            first = false;
        }
        s += "],\"sensors\":[";
        first = true;
        for (afSensorPtr se : m_world->getSensors()) {
            s += (first ? "" : ",") + string("{\"name\":") + json_text(se->getName()) +
                 ",\"qname\":" + json_text(se->getQualifiedName()) + ",\"type\":\"" + sensor_type(se->m_sensorType) +
                 "\",\"parent\":" + body_name(se->getParentBody()) + "}";
            first = false;
        }
        s += "],\"actuators\":[";
        first = true;
        for (afActuatorPtr ac : actuators()) {
            s += (first ? "" : ",") + string("{\"name\":") + json_text(ac->getName()) +
                 ",\"qname\":" + json_text(ac->getQualifiedName()) + ",\"type\":\"" +
                 (ac->m_actuatorType == afActuatorType::CONSTRAINT ? "constraint" : "invalid") +
                 "\",\"parent\":" + body_name(ac->m_parentBody) + "}";
            first = false;
        }
        s += "]}\n";
        fputs(s.c_str(), m_out);
        fflush(m_out);
    }

    // a sample lists the bodies and the joints in the order the created record lists them
    // (two bodies may share a qualified name)
    void sample(long step) {
        double t = m_world->getSimulationTime();
        string s = "{\"kind\":\"sample\",\"step\":" + to_string(step) + ",\"t\":" + num(t) +
                   ",\"clock\":" + num(m_paced ? m_cmdClock : t) + ",\"bodies\":[";
        bool first = true;
        for (afRigidBodyPtr rb : m_world->getRigidBodies()) {
            // the body's ADF body frame at this step, as Bullet holds it. AMBF's own pose
            // (getLocalPos / getLocalRot, what it publishes) is read from the motion state, which
            // Bullet's latency interpolation keeps one physics step behind (the pose integrated
            // back by m_localTime - fixedTimeStep = -dt): a body falling at 29 m/s read 29 mm
            // behind adfkit's at the same time, while the joint values (getPosition reads the
            // bodies' transforms) were of the step itself
            btTransform t = rb->m_bulletRigidBody->getCenterOfMassTransform() * rb->getInverseInertialOffsetTransform();
            btQuaternion q = t.getRotation();
            s += (first ? "[" : ",[") + num(t.getOrigin().x()) + "," + num(t.getOrigin().y()) + "," +
                 num(t.getOrigin().z()) + "," + num(q.x()) + "," + num(q.y()) + "," + num(q.z()) + "," + num(q.w()) + "]";
            first = false;
        }
        s += "],\"ghosts\":[";
        first = true;
        for (afGhostObjectPtr g : m_world->getGhostObjects()) {
            // where Bullet has the ghost (what it senses with), not AMBF's scene-graph pose
            btTransform t = g->m_bulletGhostObject->getWorldTransform();
            s += (first ? "[" : ",[") + num(t.getOrigin().x()) + "," + num(t.getOrigin().y()) + "," +
                 num(t.getOrigin().z()) + "]";
            first = false;
        }
        s += "],\"joints\":[";
        first = true;
        for (afJointPtr j : m_world->getJoints()) {
            s += (first ? "" : ",") + (j->getConstraint() ? num(j->getPosition()) : string("null"));
            first = false;
        }
        s += "]";
        if (m_contacts) s += ",\"contacts\":" + contacts();
        if (m_velocities) {
            s += ",\"velocities\":[";
            bool firstV = true;
            for (afRigidBodyPtr rb : m_world->getRigidBodies()) {
                s += (firstV ? "" : ",") + vec(rb->m_bulletRigidBody->getLinearVelocity());
                firstV = false;
            }
            s += "]";
        }
        s += "}\n";
        fputs(s.c_str(), m_out);
        fflush(m_out);
    }

    string object_name(const btCollisionObject* o) {
        for (afRigidBodyPtr rb : m_world->getRigidBodies())
            if (rb->m_bulletRigidBody == o) return json_text(rb->getQualifiedName());
        for (afGhostObjectPtr g : m_world->getGhostObjects())
            if (g->m_bulletGhostObject == o) return json_text(g->getQualifiedName());
        return "\"?\"";
    }

    // ADFKIT_PARITY_POINTS: the bodies it names, their names by collision object
    int points_side(const string& qname) const {
        if (qname.find(m_pointsA) != string::npos) return 1;
        for (const string& b : m_pointsB)
            if (qname.find(b) != string::npos) return 2;
        return 0;
    }

    static string quat(const btQuaternion& q) {
        return "[" + num(q.x()) + "," + num(q.y()) + "," + num(q.z()) + "," + num(q.w()) + "]";
    }

    static string shape_json(const btCollisionShape* c) {
        string s = "{\"type\":" + json_text(c->getName()) + ",\"margin\":" + num(c->getMargin());
        if (c->getShapeType() == CAPSULE_SHAPE_PROXYTYPE) {
            const btCapsuleShape* k = static_cast<const btCapsuleShape*>(c);
            s += ",\"radius\":" + num(k->getRadius()) + ",\"half_height\":" + num(k->getHalfHeight()) +
                 ",\"axis\":" + to_string(k->getUpAxis());
        } else if (c->getShapeType() == CONVEX_HULL_SHAPE_PROXYTYPE) {
            s += ",\"points\":" + to_string(static_cast<const btConvexHullShape*>(c)->getNumPoints());
        } else if (c->isCompound()) {
            const btCompoundShape* k = static_cast<const btCompoundShape*>(c);
            s += ",\"children\":[";
            for (int i = 0; i < k->getNumChildShapes(); i++) {
                const btTransform& tr = k->getChildTransform(i);
                s += (i ? ",{" : "{") + string("\"origin\":") + vec(tr.getOrigin()) + ",\"rot\":" + quat(tr.getRotation()) +
                     ",\"shape\":" + shape_json(k->getChildShape(i)) + "}";
            }
            s += "]";
        }
        btVector3 lo, hi;
        c->getAabb(btTransform::getIdentity(), lo, hi);
        return s + ",\"aabb\":[" + vec(lo) + "," + vec(hi) + "],\"breaking\":" + num(c->getContactBreakingThreshold(gContactBreakingThreshold)) + "}";
    }

    void write_shapes() {
        btDiscreteDynamicsWorld* w = m_world->m_bulletWorld;
        const btContactSolverInfo& si = w->getSolverInfo();
        btCollisionDispatcher* d = static_cast<btCollisionDispatcher*>(w->getDispatcher());
        string s = "{\"kind\":\"shapes\",\"double\":" + string(sizeof(btScalar) == 8 ? "true" : "false") +
                   ",\"gContactBreakingThreshold\":" + num(gContactBreakingThreshold) +
                   ",\"dispatcher_flags\":" + to_string(d->getDispatcherFlags()) + ",\"solver\":{\"iterations\":" +
                   to_string(si.m_numIterations) + ",\"erp\":" + num(si.m_erp) + ",\"erp2\":" + num(si.m_erp2) +
                   ",\"global_cfm\":" + num(si.m_globalCfm) + ",\"split_impulse\":" + to_string(si.m_splitImpulse) +
                   ",\"split_threshold\":" + num(si.m_splitImpulsePenetrationThreshold) + ",\"linear_slop\":" +
                   num(si.m_linearSlop) + ",\"mode\":" + to_string(si.m_solverMode) + "},\"bodies\":[";
        bool first = true;
        for (afRigidBodyPtr rb : m_world->getRigidBodies()) {
            string q = rb->getQualifiedName();
            if (!points_side(q)) continue;
            m_pointsNames[rb->m_bulletRigidBody] = q;
            btRigidBody* b = rb->m_bulletRigidBody;
            s += (first ? "{" : ",{") + string("\"name\":") + json_text(q) + ",\"processing\":" +
                 num(b->getContactProcessingThreshold()) + ",\"ccd\":" + num(b->getCcdMotionThreshold()) +
                 ",\"shape\":" + shape_json(b->getCollisionShape()) + "}";
            first = false;
        }
        fprintf(m_pointsOut, "%s]}\n", s.c_str());
    }

    void write_points(double t) {
        btDispatcher* d = m_world->m_bulletWorld->getDispatcher();
        for (int i = 0; i < d->getNumManifolds(); i++) {
            btPersistentManifold* m = d->getManifoldByIndexInternal(i);
            int n = m->getNumContacts();
            if (n == 0) continue;
            auto a = m_pointsNames.find(m->getBody0()), b = m_pointsNames.find(m->getBody1());
            if (a == m_pointsNames.end() || b == m_pointsNames.end()) continue;
            int sa = points_side(a->second), sb = points_side(b->second);
            if (sa == sb) continue;
            const btTransform& ta = m->getBody0()->getWorldTransform();
            const btTransform& tb = m->getBody1()->getWorldTransform();
            string s = "{\"t\":" + num(t) + ",\"A\":" + json_text(a->second) + ",\"B\":" + json_text(b->second) +
                       ",\"breaking\":" + num(m->getContactBreakingThreshold()) + ",\"posA\":" + vec(ta.getOrigin()) +
                       ",\"rotA\":" + quat(ta.getRotation()) + ",\"posB\":" + vec(tb.getOrigin()) + ",\"rotB\":" +
                       quat(tb.getRotation()) + ",\"points\":[";
            for (int k = 0; k < n; k++) {
                const btManifoldPoint& p = m->getContactPoint(k);
                s += (k ? ",[" : "[") + to_string(p.m_index0) + "," + to_string(p.m_index1) + "," + vec(p.getPositionWorldOnA()) +
                     "," + vec(p.getPositionWorldOnB()) + "," + vec(p.m_localPointA) + "," + vec(p.m_localPointB) + "," +
                     vec(p.m_normalWorldOnB) + "," + num(p.getDistance()) + "," + num(p.getAppliedImpulse()) + "," +
                     to_string(p.getLifeTime()) + "]";
            }
            fprintf(m_pointsOut, "%s]}\n", s.c_str());
        }
    }

    // the contact manifolds Bullet kept from the last step, those holding points
    string contacts() {
        btDispatcher* d = m_world->m_bulletWorld->getDispatcher();
        string s = "[";
        bool first = true;
        for (int i = 0; i < d->getNumManifolds(); i++) {
            btPersistentManifold* m = d->getManifoldByIndexInternal(i);
            int n = m->getNumContacts();
            if (n == 0) continue;
            double least = 1e30, impulse = 0.0;
            for (int k = 0; k < n; k++) {
                const btManifoldPoint& p = m->getContactPoint(k);
                least = min(least, (double)p.getDistance());
                impulse += p.getAppliedImpulse();
            }
            s += (first ? "[" : ",[") + object_name(m->getBody0()) + "," + object_name(m->getBody1()) + "," +
                 to_string(n) + "," + num(least) + "," + num(impulse) + "]";
            first = false;
        }
        return s + "]";
    }

    // AMBF 2.0 declares afObjectManager::getActuators but does not define it: its map is read
    vector<afActuatorPtr> actuators() {
        vector<afActuatorPtr> out;
        for (auto& kv : *m_world->getActuatorMap()) out.push_back(static_cast<afActuatorPtr>(kv.second));
        return out;
    }

    afJointPtr find_joint(const string& qname) {
        if (m_jointsByName.empty())
            for (afJointPtr j : m_world->getJoints()) m_jointsByName.emplace(j->getQualifiedName(), j);
        auto it = m_jointsByName.find(qname);
        return it == m_jointsByName.end() ? nullptr : it->second;
    }

    afConstraintActuator* find_actuator(const string& qname) {
        for (afActuatorPtr a : actuators())
            if (a->getQualifiedName() == qname && a->m_actuatorType == afActuatorType::CONSTRAINT)
                return static_cast<afConstraintActuator*>(a);
        return nullptr;
    }

    afRigidBodyPtr find_body(const string& qname) {
        for (afRigidBodyPtr rb : m_world->getRigidBodies())
            if (rb->getQualifiedName() == qname) return rb;
        return nullptr;
    }

    void read_commands(const char* path) {
        ifstream in(path);
        if (!in) fail(string("cannot read the command file ") + path);
        string line;
        int n = 0;
        while (getline(in, line)) {
            n++;
            if (line.empty() || line[0] == '#') continue;
            istringstream ls(line);
            Command c;
            c.line = n;
            c.value = 0.0;
            if (!(ls >> c.t >> c.kind >> c.target)) fail("command line " + to_string(n) + ": expected TIME KIND TARGET");
            string where = "command line " + to_string(n) + ": ";
            if (c.kind == "position" || c.kind == "velocity" || c.kind == "effort") {
                if (!(ls >> c.value)) fail(where + "a joint command needs a value");
                if (!find_joint(c.target)) fail(where + "no joint " + c.target);
            } else if (c.kind == "follow") {  // a path's point: kept with its joint's path, not as a command
                if (!(ls >> c.value)) fail(where + "follow needs a position");
                afJointPtr j = find_joint(c.target);
                if (!j) fail(where + "no joint " + c.target);
                if (j->m_jointType != afJointType::REVOLUTE && j->m_jointType != afJointType::PRISMATIC)
                    fail(where + "follow needs a revolute or prismatic joint: " + c.target);
                Path& p = m_paths[c.target];
                if (!p.joint) p.take(j);
                p.points.emplace_back(c.t, c.value);
                continue;
            } else if (c.kind == "grasp") {
                if (!(ls >> c.arg)) fail(where + "grasp needs a body");
                if (!find_actuator(c.target)) fail(where + "no constraint actuator " + c.target);
                if (!find_body(c.arg)) fail(where + "no rigid body " + c.arg);
                double v;
                while (ls >> v) c.numbers.push_back(v);
                if (!c.numbers.empty() && c.numbers.size() != 7)
                    fail(where + "grasp takes a body, or a body and its frame in the actuator's parent (7 numbers)");
            } else if (c.kind == "release") {
                if (!find_actuator(c.target)) fail(where + "no constraint actuator " + c.target);
            } else if (c.kind == "collide") {
                if (!(ls >> c.arg >> c.value) || (c.value != 0 && c.value != 1))
                    fail(where + "collide needs a body and 0 or 1");
                if (!find_body(c.target)) fail(where + "no rigid body " + c.target);
                if (!find_body(c.arg)) fail(where + "no rigid body " + c.arg);
            } else if (c.kind == "place" || c.kind == "force" || c.kind == "pose") {
                afRigidBodyPtr rb = find_body(c.target);
                if (!rb) fail(where + "no rigid body " + c.target);
                if (c.kind == "pose" && rb->m_bulletRigidBody->isStaticOrKinematicObject())
                    fail(where + "pose drives a dynamic body only: " + c.target);
                double v;
                while (ls >> v) c.numbers.push_back(v);
                size_t want = c.kind == "force" ? 6 : 7;
                if (c.numbers.size() != want) fail(where + c.kind + " needs " + to_string(want) + " numbers");
            } else {
                fail(where + "unknown kind " + c.kind);
            }
            m_commands.push_back(c);
        }
        stable_sort(m_commands.begin(), m_commands.end(),
                    [](const Command& a, const Command& b) { return a.t < b.t; });
        for (auto& kv : m_paths)
            stable_sort(kv.second.points.begin(), kv.second.points.end(),
                        [](const pair<double, double>& a, const pair<double, double>& b) { return a.first < b.first; });
    }

    // commands due by simulated time t take effect (a joint's command replaces its last)
    void activate(double t) {
        while (m_nextCommand < m_commands.size() && m_commands[m_nextCommand].t <= t + 1e-9) {
            const Command& c = m_commands[m_nextCommand++];
            if (c.kind == "grasp") {
                afConstraintActuator* a = find_actuator(c.target);
                afRigidBodyPtr body = find_body(c.arg);
                if (c.numbers.empty()) a->actuate(body);
                else a->actuate(body, held_at(a, body, c.numbers));
                if (m_graspRows) stiffen_last_constraint();
            } else if (c.kind == "release") {
                find_actuator(c.target)->deactuate();
            } else if (c.kind == "collide") {
                collide(find_body(c.target)->m_bulletRigidBody, find_body(c.arg)->m_bulletRigidBody, c.value != 0);
            } else if (c.kind == "place") {
                place(find_body(c.target), c.numbers);
            } else if (c.kind == "force") {
                m_forces[c.target] = c;
                m_forceBodies[c.target] = find_body(c.target);
            } else if (c.kind == "pose") {
                m_poses[c.target] = c;
                m_poseBodies[c.target] = find_body(c.target);
            } else {
                afJointPtr j = find_joint(c.target);
                m_drives[c.target] = c;
                m_driveJoints[c.target] = j;
                if (c.kind != "position") {
                    m_positionDrives.erase(c.target);
                } else if (m_paced && !m_positionDrives.count(c.target) &&
                           (j->m_jointType == afJointType::REVOLUTE || j->m_jointType == afJointType::PRISMATIC)) {
                    m_positionDrives[c.target].take(j);
                }
            }
        }
    }

    // two bodies let pass through each other (Bullet's per-object ignore list, which AMBF's
    // collision groups use too: a pair AMBF already ignores is left ignored when one is let
    // collide again), their contact manifold dropped with their broadphase pair
    void collide(btRigidBody* a, btRigidBody* b, bool on) {
        auto key = make_pair(min(a, b), max(a, b));
        if (on) {
            if (!m_passing.erase(key)) return;
            a->setIgnoreCollisionCheck(b, false);
            b->setIgnoreCollisionCheck(a, false);
            return;
        }
        if (!a->checkCollideWith(b) || !b->checkCollideWith(a)) return;  // already passing
        m_passing.insert(key);
        a->setIgnoreCollisionCheck(b, true);
        b->setIgnoreCollisionCheck(a, true);
        btBroadphaseProxy *pa = a->getBroadphaseHandle(), *pb = b->getBroadphaseHandle();
        if (pa && pb)
            m_world->m_bulletWorld->getPairCache()->removeOverlappingPair(pa, pb, m_world->m_bulletWorld->getDispatcher());
    }

    // a body set at a pose (its ADF body frame) at rest; its broadphase box moved with it (a
    // static body's is not moved by the world's own step)
    // the constraint the actuator just added (addConstraint appends it to the world's list): the
    // measurement knob ADFKIT_PARITY_GRASP_ROWS's rows and iterations on it
    void stiffen_last_constraint() {
        btDiscreteDynamicsWorld* w = m_world->m_bulletWorld;
        if (w->getNumConstraints() == 0) return;
        btTypedConstraint* c = w->getConstraint(w->getNumConstraints() - 1);
        for (int axis = 0; axis < 6; axis++) {
            c->setParam(BT_CONSTRAINT_STOP_ERP, m_graspErp, axis);
            c->setParam(BT_CONSTRAINT_STOP_CFM, m_graspCfm, axis);
        }
        if (m_graspIterations > 0) c->setOverrideNumSolverIterations(m_graspIterations);
    }

    // AMBF's offset for a grasp that holds BODY with its frame at n (x y z qx qy qz qw) in the
    // actuator's parent's frame: the actuator's frame in the body's centre-of-mass frame, as
    // afConstraintActuator::actuate(body) computes it from where the body lies, here from where
    // it is to be held (the constraint then pulls it there)
    btTransform held_at(afConstraintActuator* a, afRigidBodyPtr body, const vector<double>& n) {
        btTransform rel(btQuaternion(n[3], n[4], n[5], n[6]), btVector3(n[0], n[1], n[2]));
        afRigidBodyPtr parent = a->m_parentBody;
        btTransform parentCom = parent->m_bulletRigidBody->getCenterOfMassTransform();
        btTransform bodyCom = parentCom * parent->getInverseInertialOffsetTransform() * rel * body->getInertialOffsetTransform();
        cTransform local = a->getLocalTransform();
        cVector3d lp = local.getLocalPos();
        cMatrix3d lr = local.getLocalRot();
        btMatrix3x3 r(lr(0, 0), lr(0, 1), lr(0, 2), lr(1, 0), lr(1, 1), lr(1, 2), lr(2, 0), lr(2, 1), lr(2, 2));
        btTransform actuatorInWorld = parentCom * btTransform(r, btVector3(lp.x(), lp.y(), lp.z()));
        return bodyCom.inverse() * actuatorInWorld;
    }

    void place(afRigidBodyPtr rb, const vector<double>& n) {
        btTransform body(btQuaternion(n[3], n[4], n[5], n[6]), btVector3(n[0], n[1], n[2]));
        btTransform com = body * rb->getInertialOffsetTransform();
        btRigidBody* b = rb->m_bulletRigidBody;
        b->setCenterOfMassTransform(com);
        if (b->getMotionState()) b->getMotionState()->setWorldTransform(com);
        b->setInterpolationWorldTransform(com);
        b->setLinearVelocity(btVector3(0, 0, 0));
        b->setAngularVelocity(btVector3(0, 0, 0));
        m_world->m_bulletWorld->updateSingleAabb(b);
        rb->update(0.0);
    }

    // every joint command again each physics step, as AMBF's own ROS plugin applies the last
    // command it received (position: the joint's controller; effort: a torque for the next step)
    void drive(double dt) {
        for (auto& kv : m_poses) pose(m_poseBodies[kv.first], kv.second.numbers, dt);
        for (auto& kv : m_forces) {
            const vector<double>& n = kv.second.numbers;
            btRigidBody* b = m_forceBodies[kv.first]->m_bulletRigidBody;
            btVector3 at = btVector3(n[3], n[4], n[5]) - b->getCenterOfMassPosition();
            b->applyForce(btVector3(n[0], n[1], n[2]), at);
        }
        for (auto& kv : m_drives) {
            if (following(kv.first)) continue;
            afJointPtr j = m_driveJoints[kv.first];
            double v = kv.second.value;
            if (kv.second.kind == "position") j->commandPosition(v);
            else if (kv.second.kind == "velocity") j->commandVelocity(v);
            else j->commandEffort(v);
        }
        follow(m_cmdClock);
    }

    // ObjectCommPlugin::rigidBodyFetchCommand's TYPE_POSITION branch for a dynamic body, as is
    void pose(afRigidBodyPtr rb, const vector<double>& n, double dt) {
        btRigidBody* b = rb->m_bulletRigidBody;
        btTransform com = rb->getCOMTransform();
        btMatrix3x3 cur_rot, cmd_rot;
        cur_rot.setRotation(com.getRotation());
        cmd_rot.setRotation(btQuaternion(n[3], n[4], n[5], n[6]));
        btVector3 cmd_pos(n[0], n[1], n[2]);
        btVector3 p = rb->m_controller.computeOutput<btVector3>(com.getOrigin(), cmd_pos, dt);
        btVector3 r = rb->m_controller.computeOutput<btVector3>(cur_rot, cmd_rot, dt);
        if (rb->m_controller.m_positionOutputType == afControlType::FORCE) {
            b->applyCentralForce(p);
            b->applyTorque(r);
        } else {
            b->setLinearVelocity(p);
            b->setAngularVelocity(r);
        }
    }

    bool following(const string& joint) {
        auto it = m_paths.find(joint);
        return it != m_paths.end() && it->second.points.front().first <= m_cmdClock + 1e-9;
    }

    // each path begun: a velocity command, the path's slope at t plus the gain times the path's
    // position at t less the measured one (the joint's limits clamp the path, as commandPosition
    // clamps a set-point; a revolute joint without limits takes the shortest angle)
    void follow(double t) {
        for (auto& kv : m_paths) {
            Path& p = kv.second;
            const auto& pts = p.points;
            if (pts.front().first > t + 1e-9) continue;
            while (p.at + 1 < pts.size() && pts[p.at + 1].first <= t + 1e-9) p.at++;
            double q = pts[p.at].second, slope = 0.0;
            if (p.at + 1 < pts.size()) {
                double t0 = pts[p.at].first, t1 = pts[p.at + 1].first;
                slope = t1 > t0 ? (pts[p.at + 1].second - q) / (t1 - t0) : 0.0;
                q += slope * (t - t0);
            }
            double err = p.error(q);
            p.worst = max(p.worst, fabs(err));
            p.sum += fabs(err);
            p.n++;
            double v = slope + m_followGain * err;
            p.joint->commandVelocity(v);
        }
    }

    afWorldPtr m_world = nullptr;
    FILE* m_out = nullptr;
    double m_seconds = 0.0, m_every = 0.0, m_nextSample = 0.0;
    bool m_graspRows = false;
    double m_graspErp = 0.2, m_graspCfm = 0.0;
    int m_graspIterations = 0;
    vector<pair<double, double>> m_fine;
    long m_steps = 0;
    bool m_followGhosts = true;
    bool m_contacts = false;
    FILE* m_pointsOut = nullptr;  // ADFKIT_PARITY_POINTS
    double m_pointsFrom = 0.0, m_pointsTo = 0.0;
    string m_pointsA;
    vector<string> m_pointsB;
    map<const btCollisionObject*, string> m_pointsNames;
    bool m_velocities = false, m_stillStatic = false;
    string m_unghostName;
    bool m_unghostLinear = false, m_unghostAngular = false, m_unghostGravity = false;
    vector<btRigidBody*> m_unghosted;
    vector<btVector3> m_unghostBefore;
    vector<Command> m_commands;
    size_t m_nextCommand = 0;
    map<string, Command> m_drives;
    map<string, afJointPtr> m_driveJoints;
    map<string, afJointPtr> m_jointsByName;
    map<string, Path> m_paths;  // joints following a path (follow commands)
    double m_followGain = 100.0;
    map<string, Command> m_forces;
    map<string, afRigidBodyPtr> m_forceBodies;
    map<string, Command> m_poses;
    map<string, afRigidBodyPtr> m_poseBodies;
    set<pair<btRigidBody*, btRigidBody*>> m_passing;  // pairs a collide command let pass
    bool m_paced = false;
    double m_paceRad = 0.0, m_paceM = 0.0, m_paceWait = 0.0, m_paceMax = 0.0;
    double m_cmdClock = 0.0;
    long m_heldSteps = 0, m_giveUps = 0;
    map<string, Drive> m_positionDrives;
    map<string, long> m_givenUp;
    chrono::steady_clock::time_point m_clock;
};

AF_REGISTER_SIMULATOR_PLUGIN(AdfkitParity)
