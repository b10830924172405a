// nodelet_group: a nodelet manager that loads the nodelets listed in its ~nodelets parameter
// itself, instead of one `nodelet load` client process per nodelet.
//
// Why: each client is a ROS node of its own. Under simulated time every node subscribes to
// /clock, so a recording that publishes /clock per frame sent each tick over TCP to every idle
// client and woke it up (two threads each) on the two cores the renderer and recorder need.
// The group is still a full manager: its load_nodelet / unload_nodelet services stay up, so
// `nodelet load TYPE norm2tex_manager` adds more nodelets to it as usual.
//
//   <node pkg="norm2tex" type="nodelet_group" name="norm2tex_manager" required="true">
//     <rosparam param="nodelets">[{name: probe_sim, type: norm2tex/ProbeSimNodelet}]</rosparam>
//   </node>
// Each nodelet reads its parameters from its own private namespace (/probe_sim/...), as when
// loaded by a client; names are resolved in the group's namespace. An entry's optional
// `params: {key: value, ...}` are set in that namespace before the nodelet is loaded.
// ~num_worker_threads as for `nodelet manager`.
#include <string>
#include <vector>

#include <nodelet/loader.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "cli_arguments.hpp"

namespace {

struct NodeletSpec {
  std::string name, type;
  /// Optional: private parameters set before the nodelet is loaded (a list made by a program,
  /// e.g. scripts/hand_nodelets' one renderer per sensor, carries each one's parameters).
  XmlRpc::XmlRpcValue params;
};

/// ~nodelets as a list of {name, type}; an empty list and the reason when it is malformed.
std::vector<NodeletSpec> readNodelets(const ros::NodeHandle& pnh, std::string* why) {
  XmlRpc::XmlRpcValue list;
  if (!pnh.getParam("nodelets", list) || list.getType() != XmlRpc::XmlRpcValue::TypeArray ||
      list.size() == 0) {
    *why = "~nodelets must be a non-empty list of {name: NAME, type: PACKAGE/Type}";
    return {};
  }
  std::vector<NodeletSpec> specs;
  for (int i = 0; i < list.size(); ++i) {
    XmlRpc::XmlRpcValue& entry = list[i];
    if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct || !entry.hasMember("name") ||
        !entry.hasMember("type") || entry["name"].getType() != XmlRpc::XmlRpcValue::TypeString ||
        entry["type"].getType() != XmlRpc::XmlRpcValue::TypeString) {
      *why = "~nodelets[" + std::to_string(i) + "] is not {name: NAME, type: PACKAGE/Type}";
      return {};
    }
    NodeletSpec spec{static_cast<std::string>(entry["name"]),
                     static_cast<std::string>(entry["type"]), XmlRpc::XmlRpcValue()};
    if (entry.hasMember("params")) {
      if (entry["params"].getType() != XmlRpc::XmlRpcValue::TypeStruct) {
        *why = "~nodelets[" + std::to_string(i) + "].params is not a map of parameters";
        return {};
      }
      spec.params = entry["params"];
    }
    specs.push_back(spec);
  }
  return specs;
}

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "nodelet_group", "rosrun norm2tex nodelet_group [__name:=NAME]  (usually from a launch file)",
      "A nodelet manager that loads the nodelets of its ~nodelets parameter itself, instead of\n"
      "one `nodelet load` client process per nodelet. Its load_nodelet and unload_nodelet\n"
      "services stay up, as a `nodelet manager`'s do.");
  program.notes(
      "parameters:\n"
      "  ~nodelets: [{name: NAME, type: PACKAGE/Type[, params: {KEY: VALUE, ...}]}, ...]\n"
      "      (params: set in the nodelet's private namespace first)\n"
      "  ~num_worker_threads: as for `nodelet manager`");
  return program;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  ros::init(argc, argv, "nodelet_group");
  program.parse(argc, argv);  // no arguments of its own beyond ROS's name:=value remappings
  ros::NodeHandle pnh("~");
  std::string why;
  const std::vector<NodeletSpec> specs = readNodelets(pnh, &why);
  if (specs.empty()) {
    ROS_FATAL("nodelet_group: %s", why.c_str());
    return 1;
  }
  // With the manager's services (and its ~num_worker_threads workers), like `nodelet manager`.
  nodelet::Loader loader(true);
  for (const NodeletSpec& spec : specs) {
    const std::string name = ros::names::resolve(spec.name);
    if (spec.params.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
      for (auto& param : spec.params) ros::param::set(name + "/" + param.first, param.second);
    }
    if (!loader.load(name, spec.type, nodelet::M_string(), nodelet::V_string())) {
      ROS_FATAL(
          "nodelet_group: could not load %s of type %s (is the type in a nodelet plugin "
          "description, and its package built?)",
          name.c_str(), spec.type.c_str());
      return 1;
    }
    // A nodelet whose start-up failed stopped the node (ros::shutdown, after a FATAL saying
    // why): the ones after it are not loaded, and the group exits non-zero.
    if (!ros::ok()) return 1;
  }
  ros::spin();
  // The loader's destructor unloads the nodelets (a recorder closes its bag) before exit.
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
