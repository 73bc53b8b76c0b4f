// drive_bridge: a lockstep link between a Python controller and a paused Gazebo (Fortress or Harmonic) server.
//
//   drive_bridge WORLD CMD_TOPIC POSE_TOPIC STEP_NS MODEL_SDF NAME X Y Z YAW [DOOR_TOPIC ...]
//
// Fortress's ign-transport has no Python bindings (Harmonic's Python bindings are not in every install), and one `ign service` call costs a process start
// (about 0.1 s), so a controller at 20 Hz cannot drive through the `ign` command. This program stays up
// for a whole run. It first spawns the model in MODEL_SDF (a file) as NAME at (X, Y, Z, YAW) through
// /world/WORLD/create (one request, answered within 30 s; the server is up and paused), which saves the
// `ign service` process a spawn would otherwise cost. Then it speaks lines on stdin/stdout:
//
//   in:  "s N V W"   publish Twist(linear.x = V, angular.z = W) on CMD_TOPIC, run N physics steps
//                    (WorldControl multi_step on /world/WORLD/control, the world stays paused), wait
//                    for the pose message stamped at the end of those steps
//   out: "p T X Y YAW"  that pose: simulation time (s) and the model's world pose from POSE_TOPIC (an
//                    Odometry message, e.g. the OdometryPublisher system's, one per step)
//   in:  "d K A"     publish Double(A) on the K-th DOOR_TOPIC (a door's joint position controller: its
//                    target angle, rad); no answer, it reaches the controller before the next "s" steps
//   in:  "q"         quit
//   out: "ready" once the Twist publisher is connected to its subscriber; "error: ..." then exit 1.
//
// STEP_NS is the world's physics step in nanoseconds: the pose waited for is the first stamped at or
// after the last one plus N steps (half a step of slack for rounding).
//
// The release's message and transport headers come from a prelude that worldgen/sim/bridge.py passes with
// g++'s -include: it includes them (ignition/ for Fortress, gz/ for Harmonic) and names their namespaces
// wgmsgs and wgtransport, so this one source builds against either release.
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>


namespace
{
std::mutex lock;
std::condition_variable arrived;
int64_t stampNs = -1;
double x = 0, y = 0, yaw = 0;

void OnPose(const wgmsgs::Odometry &_msg)
{
  const auto &q = _msg.pose().orientation();
  std::lock_guard<std::mutex> guard(lock);
  stampNs = static_cast<int64_t>(_msg.header().stamp().sec()) * 1000000000 + _msg.header().stamp().nsec();
  x = _msg.pose().position().x();
  y = _msg.pose().position().y();
  yaw = std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()), 1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
  arrived.notify_all();
}

// Run _steps physics steps and stay paused; false when the world refuses.
bool Step(wgtransport::Node &_node, const std::string &_service, long _steps)
{
  wgmsgs::WorldControl request;
  request.set_pause(true);
  request.set_multi_step(static_cast<uint32_t>(_steps));
  wgmsgs::Boolean reply;
  bool result = false;
  return _node.Request(_service, request, 5000, reply, result) && result && reply.data();
}

int Fail(const std::string &_why)
{
  std::cout << "error: " << _why << std::endl;
  return 1;
}

// Create the model through the world's create service; false when it refuses or does not answer in 30 s.
// One request only: a request given up early could still be served, and a second one would then be
// refused for the name taken.
bool Spawn(wgtransport::Node &_node, const std::string &_world, char **_argv)
{
  std::ifstream file(_argv[5]);
  std::stringstream text;
  text << file.rdbuf();
  wgmsgs::EntityFactory request;
  request.set_sdf(text.str());
  request.set_name(_argv[6]);
  request.set_allow_renaming(false);
  const double yaw = std::stod(_argv[10]);
  auto *pose = request.mutable_pose();
  pose->mutable_position()->set_x(std::stod(_argv[7]));
  pose->mutable_position()->set_y(std::stod(_argv[8]));
  pose->mutable_position()->set_z(std::stod(_argv[9]));
  pose->mutable_orientation()->set_z(std::sin(yaw / 2));
  pose->mutable_orientation()->set_w(std::cos(yaw / 2));
  const std::string service = "/world/" + _world + "/create";
  wgmsgs::Boolean reply;
  bool result = false;
  return _node.Request(service, request, 30000, reply, result) && result && reply.data();
}
}  // namespace

int main(int argc, char **argv)
{
  if (argc < 11)
  {
    std::cerr << "usage: drive_bridge WORLD CMD_TOPIC POSE_TOPIC STEP_NS MODEL_SDF NAME X Y Z YAW [DOOR_TOPIC ...]"
              << std::endl;
    return 2;
  }
  const std::string world = argv[1];
  const int64_t stepNs = std::stoll(argv[4]);
  wgtransport::Node node;
  if (!Spawn(node, world, argv))
    return Fail(std::string("the world did not create the model ") + argv[6]);
  auto publisher = node.Advertise<wgmsgs::Twist>(argv[2]);
  if (!publisher || !node.Subscribe(argv[3], OnPose))
    return Fail("cannot advertise or subscribe");
  // A message published before discovery connects the subscriber is dropped: wait for it.
  for (int i = 0; i < 1000 && !publisher.HasConnections(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (!publisher.HasConnections())
    return Fail(std::string("nothing subscribes to ") + argv[2] + " within 10 s");
  // Each door's controller subscribes when the world loads; a target sent before discovery would be lost.
  std::vector<wgtransport::Node::Publisher> doors;
  for (int k = 11; k < argc; ++k)
  {
    doors.push_back(node.Advertise<wgmsgs::Double>(argv[k]));
    for (int i = 0; i < 1000 && doors.back() && !doors.back().HasConnections(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!doors.back() || !doors.back().HasConnections())
      return Fail(std::string("nothing subscribes to ") + argv[k] + " within 10 s");
  }
  std::cout << "ready" << std::endl;

  const std::string service = "/world/" + world + "/control";
  int64_t last = 0;
  std::string line;
  while (std::getline(std::cin, line))
  {
    std::istringstream in(line);
    std::string op;
    in >> op;
    if (op == "q")
      return 0;
    if (op == "d")
    {
      size_t k = 0;
      double angle = 0;
      if (!(in >> k >> angle) || k >= doors.size())
        return Fail("bad command: " + line);
      wgmsgs::Double target;
      target.set_data(angle);
      doors[k].Publish(target);
      continue;
    }
    long steps = 0;
    double v = 0, w = 0;
    if (op != "s" || !(in >> steps >> v >> w) || steps < 1)
      return Fail("bad command: " + line);
    wgmsgs::Twist twist;
    twist.mutable_linear()->set_x(v);
    twist.mutable_angular()->set_z(w);
    publisher.Publish(twist);
    if (!Step(node, service, steps))
      return Fail("world control refused " + std::to_string(steps) + " steps");
    const int64_t target = last + steps * stepNs - stepNs / 2;
    std::unique_lock<std::mutex> guard(lock);
    // The first poses of a run can miss the bridge (the model is created, and the subscription connected,
    // while the world steps): then one more step at a time until a pose at or after the target arrives.
    for (int extra = 0; !arrived.wait_for(guard, std::chrono::milliseconds(500), [&] { return stampNs >= target; });
         ++extra)
    {
      guard.unlock();
      if (extra == 60 || !Step(node, service, 1))
        return Fail("no pose on " + std::string(argv[3]) + " stamped after " + std::to_string(target) + " ns");
      guard.lock();
    }
    last = stampNs;
    std::cout.precision(17);
    std::cout << "p " << stampNs * 1e-9 << " " << x << " " << y << " " << yaw << std::endl;
  }
  return 0;
}
