// storey: the onboard executable. One binary, one verb per mode (DESIGN.md §7).
#include <cstdio>
#include <cstring>
#include <string_view>

#include "firmware/commands.hpp"

namespace {

using storey::firmware::Command;

void print_usage(FILE* out) {
  std::fprintf(out,
               "storey %s - multi-floor exploration for legged robots\n\n"
               "usage: storey <command> [options]   (storey <command> --help for details)\n\n"
               "commands:\n",
               storey::firmware::kVersion);
  for (const Command& c : storey::firmware::commands()) {
    std::fprintf(out, "  %-14s %s\n", c.name, c.summary);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  const std::string_view verb = argv[1];
  if (verb == "--help" || verb == "-h" || verb == "help") {
    print_usage(stdout);
    return 0;
  }
  if (verb == "--version") {
    std::printf("storey %s (commit %s)\n", storey::firmware::kVersion,
                storey::firmware::build_commit());
    return 0;
  }
  for (const Command& c : storey::firmware::commands()) {
    if (verb == c.name) return c.run(argc - 1, argv + 1);
  }
  std::fprintf(stderr, "storey: unknown command '%s' (see storey --help)\n", argv[1]);
  return 2;
}
