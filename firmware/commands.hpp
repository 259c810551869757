#pragma once
// The verbs of the storey executable. Each returns a process exit code: 0 success,
// 1 the work failed, 2 bad usage or bad input (with a one-line reason on stderr).
#include <span>
#include <string>

namespace storey::firmware {

inline constexpr const char* kVersion = "0.1.0";
// The commit the executable was built from (`git describe --always --dirty`; "unknown" outside a
// git checkout): run records name it, so results from different code are never mixed unseen.
const char* build_commit();

struct Command {
  const char* name;
  const char* summary;
  int (*run)(int argc, char** argv);  // argv[0] is the verb itself
};

std::span<const Command> commands();

// config/default.yaml from the working directory if there, else from the source tree.
std::string default_config_path();

int cmd_self_check(int argc, char** argv);
int cmd_check_config(int argc, char** argv);
int cmd_replay(int argc, char** argv);
int cmd_run(int argc, char** argv);
// Defined in tools/sim/sim_command.cpp (linked only when the tools are built).
int cmd_sim(int argc, char** argv);

}  // namespace storey::firmware
