#include "firmware/link_factory.hpp"

#include <cmath>

#include "drivers/can/socket_can_transport.hpp"
#include "drivers/go2/dds_link.hpp"
#include "drivers/go2/framed_link.hpp"

namespace storey::firmware {

namespace go2 = drivers::go2;

drivers::go2::LinkOptions link_options(const config::Parameters& p) {
  go2::LinkOptions o;
  o.state_timeout_ns = std::llround(p.safety.link_timeout_s * 1e9);
  o.max_command_age_ns = std::llround(p.link.max_command_age_s * 1e9);
  o.heartbeat_period_ns = std::llround(p.link.heartbeat_period_s * 1e9);
  return o;
}

std::unique_ptr<go2::RobotLink> make_robot_link(const config::Parameters& p, std::int64_t now_ns,
                                                std::string* error) {
  const go2::LinkOptions lo = link_options(p);
  std::unique_ptr<go2::RobotLink> link;
  switch (p.link.transport) {
    case config::LinkTransport::kSim:
      if (error)
        *error =
            "link.transport: sim is the in-process simulator (storey sim); storey run needs "
            "dds, udp or can";
      return nullptr;
    case config::LinkTransport::kUdp: {
      const auto& u = p.link.udp;
      link = std::make_unique<go2::UdpLink>(
          drivers::can::UdpEndpoint{u.local_address, uint16_t(u.local_port)},
          drivers::can::UdpEndpoint{u.robot_address, uint16_t(u.robot_port)}, lo, now_ns);
      break;
    }
    case config::LinkTransport::kDds: {
      go2::DdsLinkOptions o;
      o.network.domain_id = uint32_t(p.link.dds.domain_id);
      o.network.interface = p.link.dds.interface;
      o.network.allow_multicast = p.link.dds.allow_multicast;
      o.network.peers = p.link.dds.peers;
      o.link = lo;
      link = std::make_unique<go2::DdsLink>(o, now_ns);
      break;
    }
    case config::LinkTransport::kCan: {
      drivers::can::SocketCanOptions so;
      so.interface = p.link.can.interface;
      so.fd_frames = p.link.can.fd_frames;
      go2::CanChannelOptions co;
      co.fd = p.link.can.fd_frames;
      link = std::make_unique<go2::CanLink>(std::make_unique<drivers::can::SocketCanTransport>(so),
                                            co, lo, now_ns);
      break;
    }
  }
  if (!link || !link->ok()) {
    if (error)
      *error = std::string("link.transport: ") + std::string(config::to_string(p.link.transport)) +
               ": " + (link ? link->error() : "unsupported");
    return nullptr;
  }
  return link;
}

}  // namespace storey::firmware
