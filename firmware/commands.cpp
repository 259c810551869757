#include "firmware/commands.hpp"

namespace storey::firmware {

std::span<const Command> commands() {
  static const Command kCommands[] = {
      {"check-config", "validate a configuration file (errors name file, key and line)",
       cmd_check_config},
      {"self-check", "quick check of this build: clocks, scheduler, queues, default config",
       cmd_self_check},
  };
  return kCommands;
}

}  // namespace storey::firmware
