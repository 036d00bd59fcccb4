// SPDX-License-Identifier: GPL-2.0-or-later
// PhysicsWorld with ODE: upright bodies driven by bounded motors, static boxes, contacts turned into events.
#include "physics/physics_world.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <deque>
#include <mutex>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "avatar/avatar_motion.hpp"
#include "physics/contact_tracker.hpp"

namespace rfbsim::sim {
namespace {

// Every shape is centred on the plane z = 0 and every body is held there, so every contact normal is
// horizontal and nothing climbs onto anything: the simulation is planar, heights only size the shapes.
// For the same reason there is no floor geom: the plane joint is the floor, and floor contacts would only
// add friction the drive motors already model.
constexpr double kWallHeight = 2.5;  // m
// In a plane two convex shapes touch in one place, so one contact point per pair says it all; more points
// there would be copies whose friction rows make the solver's system singular.
constexpr int kMaxContactsPerPair = 1;
// Constraint force mixing for the rows without their own (friction, motors, plane joints): a touch of
// softness so that two friction rows along one wall (a body in a corner of two wall boxes) stay solvable.
constexpr double kGlobalCfm = 1e-8;

// ODE's global state is set up once per process and never torn down, since other PhysicsWorlds may live.
void init_ode() {
  static std::once_flag once;
  std::call_once(once, [] { dInitODE2(0); });
  // Builds with per-thread collision data need this on every thread that steps; elsewhere it does nothing.
  dAllocateODEDataForThread(static_cast<unsigned>(dAllocateMaskAll));
}

// Geoms carry their slot + 1 as user data, so static geometry (no data) reads as -1.
void* slot_data(int slot) { return reinterpret_cast<void*>(static_cast<std::uintptr_t>(slot + 1)); }
int slot_of(dGeomID geom) { return static_cast<int>(reinterpret_cast<std::uintptr_t>(dGeomGetData(geom))) - 1; }

// Removes any tilt, spin and height the solver left: agents stand upright and turn only as they decide.
void hold_upright(dBodyID body) {
  const dReal* p = dBodyGetPosition(body);
  dBodySetPosition(body, p[0], p[1], 0.0);
  const dReal* v = dBodyGetLinearVel(body);
  dBodySetLinearVel(body, v[0], v[1], 0.0);
  dBodySetAngularVel(body, 0.0, 0.0, 0.0);
  dMatrix3 identity;
  dRSetIdentity(identity);
  dBodySetRotation(body, identity);
}

Eigen::Vector2d planar_velocity(dBodyID body) {
  const dReal* v = dBodyGetLinearVel(body);
  return {v[0], v[1]};
}

}  // namespace

struct PhysicsWorld::Impl {
  // One agent's body, its shape, the plane joint that keeps it on the floor and the motor that drives it.
  struct Body {
    dBodyID body = nullptr;
    dGeomID geom = nullptr;
    dJointID plane = nullptr;
    dJointID motor = nullptr;
  };
  // A contact joint created in the current sub-step: who touched whom, along which normal, and the force
  // ODE applied (feedback; a deque keeps its address while more contacts are added).
  struct Touch {
    int slot_a = 0;
    int slot_b = 0;
    Eigen::Vector2d normal = Eigen::Vector2d::Zero();
    dJointFeedback feedback{};
  };

  PhysicsParams params;
  Eigen::Vector2d axis0;  // the map's axes: walls from the grid lie along them, so a body slides
  Eigen::Vector2d axis1;  // along a wall at its wanted velocity's component on the free axis
  dWorldID world = nullptr;
  dSpaceID static_space = nullptr;  // simple spaces: pairs come in insertion order (deterministic)
  dSpaceID body_space = nullptr;
  dJointGroupID contact_group = nullptr;
  Body avatar;
  std::vector<Body> people;
  std::optional<Body> robot;
  ContactTracker tracker;
  std::deque<Touch> touches;
  double contact_erp = 0.0;
  double contact_cfm = 0.0;

  Impl(const World& w, PhysicsParams p);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void add_box(Eigen::Vector2d centre, double size_x, double size_y, double height, double yaw);
  Body make_body(double x, double y, Eigen::Vector2d velocity, double radius, double height, double mass,
                 bool capsule);
  void destroy_body(Body& body);
  void sync_agents(const World& w);
  void assign_slots();
  void drive(const Body& body, double x, double y, Eigen::Vector2d wanted, double drive_force,
             double hold_force);
  void collide_pair(dGeomID g1, dGeomID g2);
  static void near_callback(void* data, dGeomID g1, dGeomID g2) { static_cast<Impl*>(data)->collide_pair(g1, g2); }
  void step(World& w, double dt);
};

PhysicsWorld::Impl::Impl(const World& w, PhysicsParams p)
    : params(p),
      axis0(std::cos(w.map.origin_yaw), std::sin(w.map.origin_yaw)),
      axis1(-std::sin(w.map.origin_yaw), std::cos(w.map.origin_yaw)) {
  assert(params.substeps >= 1 && "PhysicsParams::substeps must be at least 1");
  init_ode();
  world = dWorldCreate();
  dWorldSetGravity(world, 0.0, 0.0, 0.0);  // the plane joints carry the weight
  dWorldSetCFM(world, kGlobalCfm);
  dWorldSetContactSurfaceLayer(world, params.contact_surface_layer);
  dWorldSetContactMaxCorrectingVel(world, params.max_correcting_speed);
  static_space = dSimpleSpaceCreate(nullptr);
  body_space = dSimpleSpaceCreate(nullptr);
  contact_group = dJointGroupCreate(0);

  // Walls: the grid's blocking cells merged into rectangles, turned with the map frame.
  const GridMap& map = w.map;
  for (const WallRect& r : merge_wall_rectangles(map)) {
    const Eigen::Vector2d centre_in_map((r.first_column + 0.5 * r.columns) * map.resolution,
                                        (r.first_row + 0.5 * r.rows) * map.resolution);
    add_box(map.to_world(centre_in_map), r.columns * map.resolution, r.rows * map.resolution, kWallHeight,
            map.origin_yaw);
  }
  for (const Prop& prop : w.props) add_box({prop.x, prop.y}, prop.size_x, prop.size_y, prop.height, prop.yaw);

  // The avatar starts with its current speed, so a walking avatar does not stumble when physics begins.
  const Avatar& a = w.avatar;
  const Eigen::Vector2d heading(std::cos(a.pose.yaw), std::sin(a.pose.yaw));
  avatar = make_body(a.pose.x, a.pose.y, a.speed * heading, a.radius, params.avatar_height,
                     params.person_mass, true);
  sync_agents(w);
}

PhysicsWorld::Impl::~Impl() {
  // Geoms go with their spaces; the world takes the bodies and the plane and motor joints with it.
  dSpaceDestroy(body_space);
  dSpaceDestroy(static_space);
  dJointGroupDestroy(contact_group);
  dWorldDestroy(world);
}

void PhysicsWorld::Impl::add_box(Eigen::Vector2d centre, double size_x, double size_y, double height, double yaw) {
  dGeomID box = dCreateBox(static_space, size_x, size_y, height);
  dGeomSetPosition(box, centre.x(), centre.y(), 0.0);
  dMatrix3 rotation;
  dRFromAxisAndAngle(rotation, 0.0, 0.0, 1.0, yaw);
  dGeomSetRotation(box, rotation);
}

PhysicsWorld::Impl::Body PhysicsWorld::Impl::make_body(double x, double y, Eigen::Vector2d velocity, double radius,
                                                       double height, double mass, bool capsule) {
  Body b;
  b.body = dBodyCreate(world);
  dMass m;
  if (capsule) {
    // A capsule's length is its straight part; the caps make up the rest of the height.
    const double length = std::max(height - 2.0 * radius, 0.0);
    dMassSetCapsuleTotal(&m, mass, 3, radius, length);
    b.geom = dCreateCapsule(body_space, radius, length);
  } else {
    dMassSetCylinderTotal(&m, mass, 3, radius, height);
    b.geom = dCreateCylinder(body_space, radius, height);
  }
  dBodySetMass(b.body, &m);
  dGeomSetBody(b.geom, b.body);
  dBodySetPosition(b.body, x, y, 0.0);
  dBodySetLinearVel(b.body, velocity.x(), velocity.y(), 0.0);

  b.plane = dJointCreatePlane2D(world, nullptr);
  dJointAttach(b.plane, b.body, nullptr);
  // Drive: two velocity motors along the map's axes, each bounded by a force (legs or wheels, see drive()).
  b.motor = dJointCreateLMotor(world, nullptr);
  dJointAttach(b.motor, b.body, nullptr);
  dJointSetLMotorNumAxes(b.motor, 2);
  dJointSetLMotorAxis(b.motor, 0, 0, axis0.x(), axis0.y(), 0.0);
  dJointSetLMotorAxis(b.motor, 1, 0, axis1.x(), axis1.y(), 0.0);
  return b;
}

void PhysicsWorld::Impl::destroy_body(Body& b) {
  dJointDestroy(b.motor);
  dJointDestroy(b.plane);
  dGeomDestroy(b.geom);
  dBodyDestroy(b.body);
  b = Body{};
}

void PhysicsWorld::Impl::sync_agents(const World& w) {
  // People and the robot may come and go between ticks: bodies follow, and contact history restarts.
  bool changed = tracker.size() == 0;
  while (people.size() > w.people.size()) {
    destroy_body(people.back());
    people.pop_back();
    changed = true;
  }
  for (std::size_t i = people.size(); i < w.people.size(); ++i) {
    const Person& p = w.people[i];
    people.push_back(make_body(p.pose.x, p.pose.y, p.velocity, p.radius, p.height, params.person_mass, true));
    changed = true;
  }
  if (robot && !w.robot) {
    destroy_body(*robot);
    robot.reset();
    changed = true;
  } else if (!robot && w.robot) {
    const Robot& r = *w.robot;
    robot = make_body(r.pose.x, r.pose.y, r.velocity, r.radius, r.height, params.robot_mass, false);
    changed = true;
  }
  if (changed) assign_slots();
}

void PhysicsWorld::Impl::assign_slots() {
  // Slots in Party order: avatar, people by index, robot, and last all static geometry.
  std::vector<PartyRef> slots{{Party::Avatar, 0}};
  dGeomSetData(avatar.geom, slot_data(0));
  for (std::size_t i = 0; i < people.size(); ++i) {
    slots.push_back({Party::Person, static_cast<int>(i)});
    dGeomSetData(people[i].geom, slot_data(static_cast<int>(i) + 1));
  }
  if (robot) {
    dGeomSetData(robot->geom, slot_data(static_cast<int>(slots.size())));
    slots.push_back({Party::Robot, 0});
  }
  slots.push_back({Party::Static, 0});
  tracker = ContactTracker(std::move(slots));
}

void PhysicsWorld::Impl::drive(const Body& b, double x, double y, Eigen::Vector2d wanted, double drive_force,
                               double hold_force) {
  // The world owns the pose (another system may have moved the agent); the body keeps its velocity.
  dBodySetPosition(b.body, x, y, 0.0);
  // Standing agents brace; walking ones push with their drive force.
  constexpr double kStandingSpeed = 0.05;  // m/s
  const double force = wanted.norm() < kStandingSpeed ? hold_force : drive_force;
  dJointSetLMotorParam(b.motor, dParamFMax, force);
  dJointSetLMotorParam(b.motor, dParamFMax2, force);
  dJointSetLMotorParam(b.motor, dParamVel, wanted.dot(axis0));
  dJointSetLMotorParam(b.motor, dParamVel2, wanted.dot(axis1));
}

void PhysicsWorld::Impl::collide_pair(dGeomID g1, dGeomID g2) {
  int a = slot_of(g1);
  int b = slot_of(g2);
  if (a < 0) a = tracker.size() - 1;
  if (b < 0) b = tracker.size() - 1;
  // Lower slot first: static geometry is always second, so the first body is a real one and its feedback
  // force is the one to read.
  if (a > b) {
    std::swap(a, b);
    std::swap(g1, g2);
  }
  dContactGeom points[kMaxContactsPerPair];
  const int n = dCollide(g1, g2, kMaxContactsPerPair, points, sizeof(dContactGeom));
  const bool against_static = dGeomGetBody(g2) == nullptr;
  for (int i = 0; i < n; ++i) {
    dContact contact{};
    contact.geom = points[i];
    // The world is planar: a normal made horizontal, and friction only along the horizontal tangent (a
    // vertical friction row would duplicate the plane joint's and leave the solver a singular system).
    Eigen::Vector2d normal(points[i].normal[0], points[i].normal[1]);
    if (normal.squaredNorm() < 1e-12) continue;  // a touch from above or below: nothing to do in a plane
    normal.normalize();
    contact.geom.normal[0] = normal.x();
    contact.geom.normal[1] = normal.y();
    contact.geom.normal[2] = 0.0;
    contact.fdir1[0] = -normal.y();
    contact.fdir1[1] = normal.x();
    contact.fdir1[2] = 0.0;
    // Soft (spring and damper from the params), no bounce, Coulomb friction scaled by the normal force.
    contact.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1 | dContactFDir1 | dContactMu2;
    contact.surface.mu = against_static ? params.static_friction : params.body_friction;
    contact.surface.mu2 = 0.0;
    contact.surface.soft_erp = contact_erp;
    contact.surface.soft_cfm = contact_cfm;
    dJointID joint = dJointCreateContact(world, contact_group, &contact);
    dJointAttach(joint, dGeomGetBody(g1), dGeomGetBody(g2));
    Touch& touch = touches.emplace_back();
    touch.slot_a = a;
    touch.slot_b = b;
    touch.normal = normal;
    dJointSetFeedback(joint, &touch.feedback);
  }
}

void PhysicsWorld::Impl::step(World& w, double dt) {
  assert(dt > 0.0 && "PhysicsWorld::step needs a positive dt");
  init_ode();
  w.contacts.clear();
  sync_agents(w);

  // Wanted velocities become motor targets.
  Avatar& a = w.avatar;
  const Eigen::Vector2d heading(std::cos(a.pose.yaw), std::sin(a.pose.yaw));
  const double legs = params.person_drive_force;
  const double braced = params.person_hold_force;
  drive(avatar, a.pose.x, a.pose.y, a.speed * heading, legs, braced);
  for (std::size_t i = 0; i < people.size(); ++i) {
    const Person& p = w.people[i];
    drive(people[i], p.pose.x, p.pose.y, p.velocity, legs, braced);
  }
  const double wheels = params.robot_drive_force;
  if (robot) drive(*robot, w.robot->pose.x, w.robot->pose.y, w.robot->velocity, wheels, wheels);

  // Contact softness for this sub-step length: ERP and CFM of a spring k and damper c (ODE manual).
  const double h = dt / params.substeps;
  const double k = params.contact_stiffness;
  const double c = params.contact_damping;
  contact_erp = h * k / (h * k + c);
  contact_cfm = 1.0 / (h * k + c);

  tracker.begin_tick();
  for (int sub = 0; sub < params.substeps; ++sub) {
    // Collide bodies with bodies, then each body with the static boxes, always in the same order.
    touches.clear();
    dSpaceCollide(body_space, this, &near_callback);
    dGeomID space_geom = reinterpret_cast<dGeomID>(static_space);
    dSpaceCollide2(avatar.geom, space_geom, this, &near_callback);
    for (const Body& p : people) dSpaceCollide2(p.geom, space_geom, this, &near_callback);
    if (robot) dSpaceCollide2(robot->geom, space_geom, this, &near_callback);

    // dWorldStep (the exact LCP solver) over QuickStep: QuickStep shuffles its constraints with ODE's one
    // process-wide random stream, so two worlds in one process would disturb each other; the islands here
    // are a few bodies each, which the exact solver handles cheaply.
    dWorldStep(world, h);

    // Normal impulse per pair: the normal part of the force on the first body, times the sub-step.
    for (const Touch& t : touches) {
      const Eigen::Vector2d f1(t.feedback.f1[0], t.feedback.f1[1]);
      tracker.add(t.slot_a, t.slot_b, std::abs(f1.dot(t.normal)) * h);
    }
    dJointGroupEmpty(contact_group);
    hold_upright(avatar.body);
    for (const Body& p : people) hold_upright(p.body);
    if (robot) hold_upright(robot->body);
  }

  // Avatar: position, speed along its facing, gait by the distance actually moved.
  const dReal* pos = dBodyGetPosition(avatar.body);
  const double moved = std::hypot(pos[0] - a.pose.x, pos[1] - a.pose.y);
  a.pose.x = pos[0];
  a.pose.y = pos[1];
  a.speed = planar_velocity(avatar.body).dot(heading);
  AvatarParams gait;
  gait.stride_length = params.avatar_stride_length;
  advance_avatar_gait(gait, moved, a);

  // People: position and actual velocity (their gait is the crowd's).
  for (std::size_t i = 0; i < people.size(); ++i) {
    Person& p = w.people[i];
    const dReal* q = dBodyGetPosition(people[i].body);
    p.pose.x = q[0];
    p.pose.y = q[1];
    p.velocity = planar_velocity(people[i].body);
  }
  // Robot: position, actual velocity, and its yaw from its own yaw rate (ODE does not turn agents).
  if (robot) {
    Robot& r = *w.robot;
    const dReal* q = dBodyGetPosition(robot->body);
    r.pose.x = q[0];
    r.pose.y = q[1];
    r.pose.yaw = std::remainder(r.pose.yaw + r.yaw_rate * dt, 2.0 * std::numbers::pi);
    r.velocity = planar_velocity(robot->body);
  }
  tracker.end_tick(w.tick, params.min_impulse, w.contacts);
}

PhysicsWorld::PhysicsWorld(const World& world, PhysicsParams params)
    : impl_(std::make_unique<Impl>(world, params)) {}

PhysicsWorld::~PhysicsWorld() = default;

void PhysicsWorld::step(World& world, double dt) { impl_->step(world, dt); }

}  // namespace rfbsim::sim
