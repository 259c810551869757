#include "firmware/commands.hpp"

namespace storey::firmware {

std::span<const Command> commands() {
  static const Command kCommands[] = {
      {"check-config", "validate a configuration file (errors name file, key and line)",
       cmd_check_config},
      {"replay", "recorded LiDAR packets (pcap, pcapng, .lvx2) through ingestion and scan assembly",
       cmd_replay},
      {"run", "live exploration: LiDAR over UDP, the robot's link, real-time task threads",
       cmd_run},
      {"self-check", "quick check of this build: clocks, scheduler, queues, default config",
       cmd_self_check},
#ifdef STOREY_HAVE_SIM
      {"sim", "lockstep simulated exploration of a scene (the main job), writes a run record",
       cmd_sim},
#endif
  };
  return kCommands;
}

}  // namespace storey::firmware
