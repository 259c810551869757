// CycloneDDS configuration for the Go2 link: which NIC to bind, multicast or unicast peers.
// The XML is passed to dds_create_domain() (no CYCLONEDDS_URI needed); dds_config_xml() also
// serves to write a file for CYCLONEDDS_URI when other tools must join (see README).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace storey::drivers::go2 {

struct DdsNetworkOptions {
  uint32_t domain_id = 0;  // the Go2 uses domain 0
  // Interface name ("eth0", "enp3s0", "lo") or address; "" lets CycloneDDS choose, which on a
  // machine with Wi-Fi and the robot's Ethernet is often the wrong one.
  std::string interface;
  // Multicast discovery (the robot's network) or unicast to `peers` (loopback has no multicast).
  bool allow_multicast = true;
  std::vector<std::string> peers;       // e.g. {"127.0.0.1"} or {"192.168.123.161"}
  int max_auto_participant_index = 20;  // unicast discovery probes this many ports per peer
};

// NIC on the robot's network (192.168.123.0/24), multicast discovery as the robot does.
DdsNetworkOptions dds_robot_network(const std::string& interface);
// Loopback only, unicast discovery to 127.0.0.1 (for tests and the stand-in on one machine).
DdsNetworkOptions dds_loopback(uint32_t domain_id);

// <CycloneDDS> XML for these options.
std::string dds_config_xml(const DdsNetworkOptions& o);

}  // namespace storey::drivers::go2
