#include "drivers/go2/dds_domain.hpp"

#include <map>
#include <mutex>

namespace storey::drivers::go2 {
namespace {

struct DomainEntry {
  dds_entity_t handle = 0;
  int users = 0;
};

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<uint32_t, DomainEntry>& registry() {
  static std::map<uint32_t, DomainEntry> r;
  return r;
}

}  // namespace

DdsParticipant::DdsParticipant(const DdsNetworkOptions& options) : domain_id_(options.domain_id) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  DomainEntry& e = registry()[domain_id_];
  if (e.users == 0) {
    const std::string xml = dds_config_xml(options);
    const dds_entity_t d = dds_create_domain(domain_id_, xml.c_str());
    if (d < 0) {
      error_ = "dds_create_domain(" + std::to_string(domain_id_) + "): " + dds_strretcode(d) +
               " (config: " + xml + ")";
      registry().erase(domain_id_);
      return;
    }
    e.handle = d;
  }
  ++e.users;
  holds_domain_ = true;
  participant_ = dds_create_participant(domain_id_, nullptr, nullptr);
  if (participant_ < 0) {
    error_ = std::string("dds_create_participant: ") + dds_strretcode(participant_);
    participant_ = 0;
  }
}

DdsParticipant::~DdsParticipant() {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (participant_ > 0) dds_delete(participant_);
  if (!holds_domain_) return;
  auto it = registry().find(domain_id_);
  if (it != registry().end() && --it->second.users == 0) {
    dds_delete(it->second.handle);
    registry().erase(it);
  }
}

}  // namespace storey::drivers::go2
