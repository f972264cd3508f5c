// Simulating one frame: LiDAR sweep (ray casting ~256k rays) and camera image (465k rays).
// Goal (issue 3): ≤ 1 s per frame on one core.
#include <benchmark/benchmark.h>

#include "core/sim/simulator.h"

namespace stcalib::sim {
namespace {

const Simulator& SharedSimulator() {
  static const Simulator* simulator = [] {
    SimulatorOptions options;
    options.frames = 40;
    options.seed = 1;
    return new Simulator(options);
  }();
  return *simulator;
}

void BM_SimulateFrame(benchmark::State& state) {
  const Simulator& sim = SharedSimulator();
  int frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(sim.SimulateFrame(frame));
    frame = (frame + 7) % sim.options().frames;
  }
}
BENCHMARK(BM_SimulateFrame)->Unit(benchmark::kMillisecond);

void BM_SimulateLidarSweep(benchmark::State& state) {
  const Simulator& sim = SharedSimulator();
  std::mt19937_64 rng(1);
  size_t points = 0;
  for (auto _ : state) {
    const SimulatedSweep sweep =
        SimulateLidarSweep(sim.scene(), sim.trajectory(), sim.T_lidar_imu().inverse(),
                           sim.lidar_model(), sim.LidarMidTime(10), sim.SweepDuration(), &rng);
    points = sweep.scan.size();
  }
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_SimulateLidarSweep)->Unit(benchmark::kMillisecond);

void BM_RenderCameraImage(benchmark::State& state) {
  const Simulator& sim = SharedSimulator();
  std::mt19937_64 rng(1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(RenderCameraImage(sim.scene(), sim.trajectory(), sim.camera_rig(),
                                               sim.Timing(10).camera_time_s, &rng));
  }
}
BENCHMARK(BM_RenderCameraImage)->Unit(benchmark::kMillisecond);

void BM_BuildSimulator(benchmark::State& state) {
  SimulatorOptions options;
  options.frames = 40;
  for (auto _ : state) benchmark::DoNotOptimize(Simulator(options));
}
BENCHMARK(BM_BuildSimulator)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stcalib::sim
