// A scene of primitive bodies played in AMBF's own Bullet (its external/bullet, linked from its
// build), made as AMBF's afRigidBody and afJoint make them, stepped at 1 ms as AMBF steps it; with
// "two" on the command line the solver also solves a second friction direction per contact, as
// PyBullet's (btMultiBodyDynamicsWorld sets SOLVER_USE_2_FRICTION_DIRECTIONS) and nothing else
// changes; with "fresh" too, each contact's friction rows start every step from zero, as Bullet's
// since 2019 and PyBullet's do (bench/ambf_friction.py builds this program with a copy of AMBF's
// btSequentialImpulseConstraintSolver.cpp whose friction restart reads gFrictionFromZero).
// Built and driven by bench/ambf_friction.py, which writes the scene on stdin:
//   steps every                                   (physics steps, a sample every so many)
//   body MASS IX IY IZ  PX PY PZ QX QY QZ QW  FRICTION ROLLING RESTITUTION LINDAMP ANGDAMP N
//   shape KIND AXIS MARGIN D1 D2 D3  PX PY PZ QX QY QZ QW     (N of them, in the body's COM frame)
//   fixed PARENT CHILD  PX PY PZ QX QY QZ QW  PX PY PZ QX QY QZ QW  (its frames in their COM frames)
// KIND: box (D: half extents), sphere (D1 radius), cylinder, capsule, cone (D1 radius, D2 height
// as ADF gives it), plane (D: normal, the pose's x its offset). Prints each sample's COM poses:
//   T I PX PY PZ QX QY QZ QW
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <btBulletDynamicsCommon.h>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

extern bool gFrictionFromZero;

static btCollisionShape* shape(const std::string& kind, char axis, double d1, double d2, double d3) {
    if (kind == "box") return new btBoxShape(btVector3(d1, d2, d3));
    if (kind == "sphere") return new btSphereShape(d1);
    if (kind == "cylinder") {  // afShapeUtils::createCollisionShape: half extents (radius, radius, height/2) about the axis
        if (axis == 'x') return new btCylinderShapeX(btVector3(d2 / 2, d1, d1));
        if (axis == 'y') return new btCylinderShape(btVector3(d1, d2 / 2, d1));
        return new btCylinderShapeZ(btVector3(d1, d1, d2 / 2));
    }
    if (kind == "capsule") {  // Bullet's height is between the two caps' centres
        if (axis == 'x') return new btCapsuleShapeX(d1, d2 - 2 * d1);
        if (axis == 'y') return new btCapsuleShape(d1, d2 - 2 * d1);
        return new btCapsuleShapeZ(d1, d2 - 2 * d1);
    }
    if (kind == "cone") {
        if (axis == 'x') return new btConeShapeX(d1, d2);
        if (axis == 'y') return new btConeShape(d1, d2);
        return new btConeShapeZ(d1, d2);
    }
    return nullptr;
}

int main(int argc, char** argv) {
    bool two = false;
    for (int i = 1; i < argc; i++) {
        two = two || !strcmp(argv[i], "two");
        gFrictionFromZero = gFrictionFromZero || !strcmp(argv[i], "fresh");
    }
    auto* config = new btSoftBodyRigidBodyCollisionConfiguration();
    auto* dispatcher = new btCollisionDispatcher(config);
    auto* world = new btDiscreteDynamicsWorld(dispatcher, new btDbvtBroadphase(), new btSequentialImpulseConstraintSolver, config);
    world->setGravity(btVector3(0, 0, -9.81));
    if (two) world->getSolverInfo().m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
    long steps = 0, every = 1;
    std::cin >> steps >> every;
    std::vector<btRigidBody*> bodies;
    std::string word;
    while (std::cin >> word) {
        btVector3 p;
        btQuaternion q;
        auto pose = [&]() {
            double x, y, z, qx, qy, qz, qw;
            std::cin >> x >> y >> z >> qx >> qy >> qz >> qw;
            p.setValue(x, y, z);
            q.setValue(qx, qy, qz, qw);
        };
        if (word == "body") {
            double m, ix, iy, iz, fr, rf, rest, ld, ad, gx, gy, gz;
            int n;
            std::cin >> m >> ix >> iy >> iz;
            pose();
            btTransform at(q, p);
            std::cin >> fr >> rf >> rest >> ld >> ad >> gx >> gy >> gz >> n;
            btCollisionShape* col = nullptr;
            auto* compound = new btCompoundShape();
            for (int i = 0; i < n; i++) {
                std::string s, kind;
                char axis;
                double margin, d1, d2, d3;
                std::cin >> s >> kind >> axis >> margin >> d1 >> d2 >> d3;
                pose();
                if (kind == "plane" && n == 1) {  // a lone plane is not put in a compound (afRigidBody)
                    col = new btStaticPlaneShape(btVector3(d1, d2, d3), p.x());
                    col->setMargin(margin);
                    continue;
                }
                btCollisionShape* child = shape(kind, axis, d1, d2, d3);
                if (!child) {
                    std::cerr << "unknown shape " << kind << "\n";
                    return 2;
                }
                child->setMargin(margin);
                compound->addChildShape(btTransform(q, p), child);
            }
            if (!col) col = compound;
            btRigidBody::btRigidBodyConstructionInfo info(m, new btDefaultMotionState(at), col, btVector3(ix, iy, iz));
            auto* body = new btRigidBody(info);
            body->setFriction(fr);
            body->setRollingFriction(rf);
            body->setRestitution(rest);
            body->setDamping(ld, ad);
            body->setActivationState(DISABLE_DEACTIVATION);  // afRigidBody, every body
            body->setSleepingThresholds(0, 0);
            world->addRigidBody(body);
            body->setGravity(btVector3(gx, gy, gz));  // the world's, or the body's or model's `gravity` (afRigidBody)
            bodies.push_back(body);
        } else if (word == "fixed") {
            int a, b;
            std::cin >> a >> b;
            pose();
            btTransform frame_a(q, p);
            pose();
            world->addConstraint(new btFixedConstraint(*bodies[a], *bodies[b], frame_a, btTransform(q, p)), true);
        } else {
            std::cerr << "unknown entry " << word << "\n";
            return 2;
        }
    }
    for (long k = 0; k <= steps; k++) {
        if (k > 0) world->stepSimulation(0.001, 1, 0.001);
        if (k % every && k != steps) continue;
        for (size_t i = 0; i < bodies.size(); i++) {
            const btTransform& t = bodies[i]->getWorldTransform();
            btQuaternion r = t.getRotation();
            printf("%.6f %zu %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k * 0.001, i, t.getOrigin().x(), t.getOrigin().y(),
                   t.getOrigin().z(), r.x(), r.y(), r.z(), r.w());
        }
    }
    return 0;
}
