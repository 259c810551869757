#include "drivers/go2/dds_config.hpp"

namespace storey::drivers::go2 {

DdsNetworkOptions dds_robot_network(const std::string& interface) {
  DdsNetworkOptions o;
  o.interface = interface;
  return o;
}

DdsNetworkOptions dds_loopback(uint32_t domain_id) {
  DdsNetworkOptions o;
  o.domain_id = domain_id;
  o.interface = "lo";
  o.allow_multicast = false;
  o.peers = {"127.0.0.1"};
  return o;
}

std::string dds_config_xml(const DdsNetworkOptions& o) {
  std::string x = "<CycloneDDS><Domain id=\"any\"><General>";
  if (!o.interface.empty()) {
    x += "<Interfaces><NetworkInterface name=\"" + o.interface + "\"/></Interfaces>";
  }
  x += o.allow_multicast ? "<AllowMulticast>default</AllowMulticast>"
                         : "<AllowMulticast>false</AllowMulticast>";
  x += "</General><Discovery>";
  if (!o.peers.empty()) {
    x += "<Peers>";
    for (const std::string& p : o.peers) x += "<Peer address=\"" + p + "\"/>";
    x += "</Peers>";
  }
  x += "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>" +
       std::to_string(o.max_auto_participant_index) + "</MaxAutoParticipantIndex>";
  x += "</Discovery></Domain></CycloneDDS>";
  return x;
}

}  // namespace storey::drivers::go2
