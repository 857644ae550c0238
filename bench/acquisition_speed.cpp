// Time per view on the emulators in real time (the virtual platform, the LMS111 driver and the
// stage controller, ROS-free): a continuous sweep at 25 Hz / 0.25 deg and 50 Hz / 0.5 deg
// (targets 8.5 s and 4.5 s against the device's own 8 s and 4 s), and step-and-scan, the
// paper's way (it took 45 s a view). A view alternates direction, as the assembler sweeps.
#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "dormant_tree_modeling/acquisition/sweep_recorder.h"
#include "dormant_tree_modeling/aerotech/stage_controller.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/driver.h"
#include "dormant_tree_modeling/lms111/laser_scan.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/virtual_platform.h"
#include "peak_memory.h"

using namespace dormant_tree_modeling;

namespace {

double wallClock() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The virtual platform with the driver and the stage controller connected to it.
class Rig {
 public:
  explicit Rig(double frequency) {
    simulation::VirtualPlatformConfig o;
    o.laser.cola_a_port = 0;
    o.laser.cola_b_port = -1;
    o.stage_port = 0;
    o.scan_frequency_hz = frequency;
    platform_ =
        std::make_unique<simulation::VirtualPlatform>(simulation::generateOrchard({}, 1).scene, o);
    aerotech::StageConfig sc;
    sc.controller.host = "127.0.0.1";
    sc.controller.port = platform_->stagePort();
    stage_ = std::make_unique<aerotech::StageController>(sc);
    stage_->setUp();
    feedback_ = std::thread([this] {
      while (!stop_) {
        try {
          const double before = wallClock();
          const double theta = stage_->feedback().rotary;
          const double after = wallClock();
          recorder_.addPosition(0.5 * (before + after), theta * M_PI / 180.0);
        } catch (const Error&) {
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // 50 Hz, as the node
      }
    });
    lms111::DriverConfig dc;
    dc.host = "127.0.0.1";
    dc.port = platform_->laserPort();
    dc.scan_frequency_hz = frequency;
    dc.angular_resolution_deg = frequency == 25.0 ? 0.25 : 0.5;
    driver_ = std::make_unique<lms111::Lms111Driver>(dc, [this](const lms111::StampedScan& s) {
      const lms111::LaserScanData d = lms111::toLaserScan(s.telegram, 0.5, 20.0);
      acquisition::SweepLine l;
      l.stamp = s.stamp_s;
      l.time_increment = d.time_increment;
      l.phi0 = d.angle_min - lms111::DEVICE_TO_ROS_ANGLE_DEG * M_PI / 180.0;
      l.phi_step = d.angle_increment;
      l.ranges = d.ranges;
      recorder_.addLine(std::move(l), d.scan_time);
    });
    driver_->start();
    while (!recorder_.scanPeriod(wallClock(), 1.0))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ~Rig() {
    stop_ = true;
    feedback_.join();
    driver_->stop();
  }

  acquisition::SweepIo io() {
    acquisition::SweepIo io;
    io.now = wallClock;
    io.move_rotary = [this](double target, double velocity) {
      aerotech::MoveRequest q;
      q.axis = "X";
      q.target = target;
      q.velocity = velocity;
      const auto r = stage_->move(q);
      if (!r.success())
        throw Error(ErrorCode::IO_FAILURE, r.message);
    };
    io.scan_period = [this] {
      const auto period = recorder_.scanPeriod(wallClock(), 1.0);
      if (!period)
        throw Error(ErrorCode::IO_FAILURE, "the laser stopped streaming");
      return *period;
    };
    recorder_.bind(io);
    return io;
  }

 private:
  std::unique_ptr<simulation::VirtualPlatform> platform_;
  std::unique_ptr<aerotech::StageController> stage_;
  std::unique_ptr<lms111::Lms111Driver> driver_;
  std::thread feedback_;
  std::atomic<bool> stop_{false};
  acquisition::SweepRecorder recorder_;
};

void BM_View(benchmark::State& state) {
  const double frequency = static_cast<double>(state.range(0));
  const bool continuous = state.range(1) == 1;
  Rig rig(frequency);
  acquisition::SweepConfig s;
  s.continuous = continuous;
  // The first sweep starts from where homing left the stage: put it at one end first.
  rig.io().move_rotary(s.theta_min_deg - s.margin_deg, 0.0);
  acquisition::RangeImage image;
  for (auto _ : state) {
    try {
      image = acquisition::runSweep(rig.io(), s, nullptr);
    } catch (const Error& e) {
      state.SkipWithError(e.what());
      break;
    }
  }
  state.counters["rows"] = image.rows;
  state.counters["cols"] = image.cols;
  state.counters["device_s"] = 200.0 / frequency;  // 200 lines at the scan rate
  state.counters["paper_s"] = 45.0;
  bench::reportPeakMemory(state);
  state.SetLabel(continuous ? "continuous sweep" : "step-and-scan");
}
BENCHMARK(BM_View)
    ->Args({25, 1})
    ->Args({50, 1})
    ->Args({25, 0})
    ->Args({50, 0})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(2)
    ->Repetitions(1);

}  // namespace

BENCHMARK_MAIN();
