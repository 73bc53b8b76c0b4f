// sdf_check: a strict SDFormat checker built on libsdformat (sdformat12).
//
//   sdf_check [--dump] FILE
//
// libsdformat's default configuration only warns about an element it does not
// know and then drops it, so a misspelt <statik> would load as a dynamic model.
// Here every unrecognised element, every warning and every deprecation is an
// error, and the file is checked twice:
//
//   1. against the spec of the version the file declares, without conversion,
//      so a 1.6 file that uses an element new in 1.7+ is rejected (after
//      conversion to 1.9 it would look fine);
//   2. with sdf::Root::Load, which converts to the newest version and builds
//      the DOM, frame graph and pose graph (joint parents, relative_to names,
//      cycles, etc.).
//
// Every error is printed on stderr as "error: ..."; the exit status is 0 when
// there is none, 1 when there is any, 2 on a usage problem. With --dump, what
// libsdformat understood is printed on stdout, one fact per line, so a test can
// compare it with what the exporter meant to write without parsing XML itself.
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>

#include <sdf/sdf.hh>

namespace
{
sdf::ParserConfig StrictConfig()
{
  sdf::ParserConfig config;
  config.SetWarningsPolicy(sdf::EnforcementPolicy::ERR);
  config.SetUnrecognizedElementsPolicy(sdf::EnforcementPolicy::ERR);
  config.SetDeprecatedElementsPolicy(sdf::EnforcementPolicy::ERR);
  return config;
}

// The version attribute of the <sdf> root, or "" when there is none.
std::string DeclaredVersion(const std::string &_path)
{
  std::ifstream in(_path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string body = text.str();
  static const std::regex pattern(
      "<sdf[^>]*\\sversion\\s*=\\s*[\"']([0-9.]+)[\"']");
  std::smatch match;
  if (std::regex_search(body, match, pattern))
    return match[1];
  return "";
}

// Stage 1: the file against its own version's spec, no conversion.
sdf::Errors NativeCheck(const std::string &_path, const std::string &_version,
                        const sdf::ParserConfig &_config)
{
  sdf::Errors errors;
  // The spec that sdf::init loads follows the process-wide SDF version, so it
  // is switched for this read and restored before the Root::Load stage.
  const std::string latest = sdf::SDF::Version();
  sdf::SDF::Version(_version);
  sdf::SDFPtr doc(new sdf::SDF());
  if (!sdf::init(doc))
  {
    errors.push_back({sdf::ErrorCode::FILE_READ,
        "no SDFormat spec for declared version " + _version});
  }
  else
  {
    sdf::readFileWithoutConversion(_path, _config, doc, errors);
  }
  sdf::SDF::Version(latest);
  return errors;
}

std::string Vec(const ignition::math::Vector3d &_v)
{
  std::ostringstream out;
  out.precision(9);
  out << _v.X() << " " << _v.Y() << " " << _v.Z();
  return out.str();
}

std::string PoseText(const ignition::math::Pose3d &_p)
{
  std::ostringstream out;
  out.precision(9);
  out << _p.Pos().X() << " " << _p.Pos().Y() << " " << _p.Pos().Z() << " "
      << _p.Rot().Roll() << " " << _p.Rot().Pitch() << " " << _p.Rot().Yaw();
  return out.str();
}

std::string Color(const ignition::math::Color &_c)
{
  std::ostringstream out;
  out.precision(6);
  out << _c.R() << " " << _c.G() << " " << _c.B() << " " << _c.A();
  return out.str();
}

void DumpGeometry(const std::string &_prefix, const sdf::Geometry *_geom)
{
  if (!_geom)
    return;
  std::cout << _prefix;
  if (_geom->BoxShape())
    std::cout << " box " << Vec(_geom->BoxShape()->Size());
  else if (_geom->CylinderShape())
    std::cout << " cylinder " << _geom->CylinderShape()->Radius() << " "
              << _geom->CylinderShape()->Length();
  else if (_geom->SphereShape())
    std::cout << " sphere " << _geom->SphereShape()->Radius();
  else if (_geom->MeshShape())
    std::cout << " mesh " << _geom->MeshShape()->Uri() << " "
              << Vec(_geom->MeshShape()->Scale());
  else
    std::cout << " other";
  std::cout << "\n";
}

// Friction as written under surface/friction/ode (the DOM of sdformat12 has
// no accessor for it, so read the element without adding defaults).
void DumpFriction(const std::string &_prefix, const sdf::ElementPtr &_elem)
{
  sdf::ElementPtr e = _elem;
  for (const char *name : {"surface", "friction", "ode"})
  {
    if (!e || !e->HasElement(name))
      return;
    e = e->FindElement(name);
  }
  std::cout << _prefix << " " << e->Get<double>("mu") << " "
            << e->Get<double>("mu2") << "\n";
}

std::string JointTypeName(sdf::JointType _type)
{
  switch (_type)
  {
    case sdf::JointType::FIXED: return "fixed";
    case sdf::JointType::REVOLUTE: return "revolute";
    case sdf::JointType::PRISMATIC: return "prismatic";
    case sdf::JointType::CONTINUOUS: return "continuous";
    default: return "other";
  }
}

// libsdformat does not open mesh files, so a wrong relative uri would only
// show up in the simulator: check that each one names a file beside the world.
void CheckMeshFiles(const sdf::Root &_root, const std::string &_path,
                    sdf::Errors &_errors)
{
  const std::string::size_type slash = _path.rfind('/');
  const std::string folder =
      slash == std::string::npos ? "." : _path.substr(0, slash);
  auto check = [&](const sdf::Geometry *_geom)
  {
    if (!_geom || !_geom->MeshShape())
      return;
    std::string uri = _geom->MeshShape()->Uri();
    if (uri.rfind("file://", 0) == 0)
      uri = uri.substr(7);
    else if (uri.find("://") != std::string::npos)
      return;  // model://, package://, http://: not a local relative file
    const std::string file = uri[0] == '/' ? uri : folder + "/" + uri;
    if (!std::ifstream(file).good())
      _errors.push_back({sdf::ErrorCode::URI_LOOKUP,
          "mesh file [" + _geom->MeshShape()->Uri() + "] not found at " +
          file});
  };
  for (uint64_t w = 0; w < _root.WorldCount(); ++w)
  {
    const sdf::World *world = _root.WorldByIndex(w);
    for (uint64_t m = 0; m < world->ModelCount(); ++m)
    {
      const sdf::Model *model = world->ModelByIndex(m);
      for (uint64_t k = 0; k < model->LinkCount(); ++k)
      {
        const sdf::Link *link = model->LinkByIndex(k);
        for (uint64_t c = 0; c < link->CollisionCount(); ++c)
          check(link->CollisionByIndex(c)->Geom());
        for (uint64_t v = 0; v < link->VisualCount(); ++v)
          check(link->VisualByIndex(v)->Geom());
      }
    }
  }
}

void Dump(const sdf::Root &_root)
{
  std::cout.precision(9);
  for (uint64_t w = 0; w < _root.WorldCount(); ++w)
  {
    const sdf::World *world = _root.WorldByIndex(w);
    std::cout << "world " << world->Name() << "\n";
    std::cout << "gravity " << Vec(world->Gravity()) << "\n";
    const sdf::Physics *physics = world->PhysicsDefault();
    if (physics)
    {
      std::cout << "physics " << physics->MaxStepSize() << " "
                << physics->RealTimeFactor() << "\n";
      std::cout << "update_rate "
                << physics->Element()->Get<double>("real_time_update_rate")
                << "\n";
    }
    for (uint64_t l = 0; l < world->LightCount(); ++l)
      std::cout << "light " << world->LightByIndex(l)->Name() << "\n";
    for (uint64_t m = 0; m < world->ModelCount(); ++m)
    {
      const sdf::Model *model = world->ModelByIndex(m);
      const std::string mname = model->Name();
      ignition::math::Pose3d pose;
      model->SemanticPose().Resolve(pose, "world");
      std::cout << "model " << mname << " static " << model->Static()
                << " pose " << PoseText(pose) << "\n";
      for (uint64_t k = 0; k < model->LinkCount(); ++k)
      {
        const sdf::Link *link = model->LinkByIndex(k);
        const std::string lname = mname + "::" + link->Name();
        // Relative to the model frame; the test composes it with the model's.
        link->SemanticPose().Resolve(pose, "__model__");
        std::cout << "link " << lname << " pose " << PoseText(pose)
                  << " mass " << link->Inertial().MassMatrix().Mass()
                  << " inertia "
                  << Vec(link->Inertial().MassMatrix().DiagonalMoments())
                  << "\n";
        for (uint64_t c = 0; c < link->CollisionCount(); ++c)
        {
          const sdf::Collision *col = link->CollisionByIndex(c);
          const std::string prefix = "collision " + lname + "::" + col->Name();
          DumpGeometry(prefix, col->Geom());
          DumpFriction("friction " + lname + "::" + col->Name(),
                       col->Element());
        }
        for (uint64_t v = 0; v < link->VisualCount(); ++v)
        {
          const sdf::Visual *vis = link->VisualByIndex(v);
          const std::string prefix = "visual " + lname + "::" + vis->Name();
          DumpGeometry(prefix, vis->Geom());
          if (vis->Material())
            std::cout << "material " << lname << "::" << vis->Name() << " "
                      << Color(vis->Material()->Ambient()) << " "
                      << Color(vis->Material()->Diffuse()) << "\n";
        }
      }
      for (uint64_t j = 0; j < model->JointCount(); ++j)
      {
        const sdf::Joint *joint = model->JointByIndex(j);
        std::cout << "joint " << mname << "::" << joint->Name() << " type "
                  << JointTypeName(joint->Type()) << " parent "
                  << joint->ParentLinkName() << " child "
                  << joint->ChildLinkName();
        const sdf::JointAxis *axis = joint->Axis(0);
        if (axis)
          std::cout << " axis " << Vec(axis->Xyz()) << " limits "
                    << axis->Lower() << " " << axis->Upper() << " damping "
                    << axis->Damping();
        std::cout << "\n";
      }
    }
    // Actors: each script as libsdformat read it, for the trajectory tests.
    for (uint64_t a = 0; a < world->ActorCount(); ++a)
    {
      const sdf::Actor *actor = world->ActorByIndex(a);
      std::cout << "actor " << actor->Name() << " loop " << actor->ScriptLoop() << "\n";
      for (uint64_t t = 0; t < actor->TrajectoryCount(); ++t)
      {
        const sdf::Trajectory *traj = actor->TrajectoryByIndex(t);
        std::cout << "trajectory " << actor->Name() << " " << traj->Id()
                  << " tension " << traj->Tension() << "\n";
        std::cout.precision(12);
        for (uint64_t k = 0; k < traj->WaypointCount(); ++k)
        {
          const sdf::Waypoint *wp = traj->WaypointByIndex(k);
          std::cout << "waypoint " << actor->Name() << " " << traj->Id() << " "
                    << wp->Time() << " " << PoseText(wp->Pose()) << "\n";
        }
        std::cout.precision(9);
      }
    }
  }
}
}  // namespace

int main(int _argc, char **_argv)
{
  bool dump = false;
  std::string path;
  for (int i = 1; i < _argc; ++i)
  {
    const std::string arg = _argv[i];
    if (arg == "--dump")
      dump = true;
    else if (path.empty())
      path = arg;
    else
      path = "";
  }
  if (path.empty())
  {
    std::cerr << "usage: sdf_check [--dump] FILE\n";
    return 2;
  }
  if (!std::ifstream(path).good())
  {
    std::cerr << "error: cannot read " << path << "\n";
    return 2;
  }

  const sdf::ParserConfig config = StrictConfig();
  sdf::Errors errors;
  const std::string version = DeclaredVersion(path);
  if (version.empty())
    errors.push_back({sdf::ErrorCode::ATTRIBUTE_MISSING,
        "the <sdf> element declares no version"});
  else
    errors = NativeCheck(path, version, config);

  sdf::Root root;
  const sdf::Errors loadErrors = root.Load(path, config);
  errors.insert(errors.end(), loadErrors.begin(), loadErrors.end());
  if (loadErrors.empty())
    CheckMeshFiles(root, path, errors);

  for (const sdf::Error &e : errors)
    std::cerr << "error: " << e.Message() << "\n";
  if (errors.empty() && dump)
    Dump(root);
  return errors.empty() ? 0 : 1;
}
