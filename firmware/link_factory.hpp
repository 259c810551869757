#pragma once
// The robot link named by the configuration's `link` section (DESIGN §3: the Go2's DDS interface,
// the UDP link of bridges and hardware-in-the-loop, CAN over SocketCAN). Non-RT: called once at
// start-up by `storey run`.
#include <cstdint>
#include <memory>
#include <string>

#include "config/parameters.hpp"
#include "drivers/go2/robot_link.hpp"

namespace storey::firmware {

// Link options from the configuration: link loss after safety.link_timeout_s, commands older
// than link.max_command_age_s refused, host heartbeat every link.heartbeat_period_s.
drivers::go2::LinkOptions link_options(const config::Parameters& p);

// The link, opened. nullptr with a one-line reason naming the setting in `error` when the
// transport cannot be used here (`sim`: the in-process simulator has no live link) or failed to
// open (address in use, no such interface, DDS error).
std::unique_ptr<drivers::go2::RobotLink> make_robot_link(const config::Parameters& p,
                                                         std::int64_t now_ns, std::string* error);

}  // namespace storey::firmware
