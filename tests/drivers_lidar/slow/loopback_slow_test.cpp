// The 10 s loopback runs at 2x the sensors' packet rates (CTest label "slow").
#include "../loopback_harness.hpp"

namespace storey::drivers::lidar {
namespace {

TEST(UdpReceiverSlow, LoopbackVlp16TwiceRate10s) {
  testing::LoopbackResult r;
  testing::run_loopback(SensorModel::vlp16, 2 * 754.0, 10.0, r);
  testing::expect_lossless(r);
}

TEST(UdpReceiverSlow, LoopbackMid360TwiceRate10s) {
  testing::LoopbackResult r;
  testing::run_loopback(SensorModel::mid360, 2 * 2083.0, 10.0, r);
  testing::expect_lossless(r);
}

}  // namespace
}  // namespace storey::drivers::lidar
