#include <filesystem>
#include <string>

#include "firmware/commands.hpp"

#ifndef STOREY_CONFIG_DIR
#define STOREY_CONFIG_DIR "config"
#endif

namespace storey::firmware {

std::string default_config_path() {
  if (std::filesystem::exists("config/default.yaml")) return "config/default.yaml";
  return std::string(STOREY_CONFIG_DIR) + "/default.yaml";
}

}  // namespace storey::firmware
