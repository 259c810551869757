// A CycloneDDS participant on a domain configured from DdsNetworkOptions. CycloneDDS allows one
// domain instance per id per process, so the firmware's DdsLink and an in-process robot stand-in
// share it: the first user creates it with its configuration, the last one deletes it. Setup
// path only (a mutex guards the registry); never called from a periodic task.
#pragma once

#include <dds/dds.h>

#include <string>

#include "drivers/go2/dds_config.hpp"

namespace storey::drivers::go2 {

class DdsParticipant {
 public:
  explicit DdsParticipant(const DdsNetworkOptions& options);
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  bool ok() const { return participant_ > 0; }
  const std::string& error() const { return error_; }
  dds_entity_t handle() const { return participant_; }

 private:
  uint32_t domain_id_;
  dds_entity_t participant_ = 0;
  bool holds_domain_ = false;
  std::string error_;
};

}  // namespace storey::drivers::go2
