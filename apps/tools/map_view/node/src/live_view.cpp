// map_view live: DDS readers -> FleetViewBuilder (under a mutex) -> render on the
// main thread every period -> window and/or DIR/map_latest.png.
#include <sys/types.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>

#include <opencv2/highgui.hpp>

#include "pixyslam/map_view/map_view_commands.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/map_view/image_output.h"
#include "pixyslam/map_view/msg_conversion.h"

namespace pixyslam::map_view {
namespace {

constexpr const char* kWindow = "pixyslam map_view";

bool display_set() {
  const char* x = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x != nullptr && *x != '\0') || (wayland != nullptr && *wayland != '\0');
}

// Opening a window in a child first: a GUI toolkit that cannot reach the
// display may abort the process instead of throwing.
bool window_works() {
  const pid_t child = fork();
  if (child < 0) return false;
  if (child == 0) {
    const int null_fd = open("/dev/null", O_WRONLY);
    if (null_fd >= 0) {
      dup2(null_fd, STDOUT_FILENO);
      dup2(null_fd, STDERR_FILENO);
    }
    try {
      cv::namedWindow("pixyslam map_view probe", cv::WINDOW_AUTOSIZE);
      cv::destroyAllWindows();
    } catch (...) {
      _exit(1);
    }
    _exit(0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  int status = 0;
  while (waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

bool open_window() {
  if (!display_set() || !window_works()) return false;
  try {
    cv::namedWindow(kWindow, cv::WINDOW_AUTOSIZE);
    return true;
  } catch (const cv::Exception&) {
    return false;
  }
}

// False once the user closed the window or pressed q / Esc.
bool window_alive(int wait_ms) {
  const int key = cv::waitKey(wait_ms);
  if (key == 'q' || key == 'Q' || key == 27) return false;
  try {
    return cv::getWindowProperty(kWindow, cv::WND_PROP_VISIBLE) >= 1.0;
  } catch (const cv::Exception&) {
    return false;
  }
}

struct Shared {
  std::mutex mutex;
  FleetViewBuilder builder;  // every robot on the domain
  bool changed = false;
  explicit Shared(double min_step_m) : builder(min_step_m) {}
};

}  // namespace

int run_live(const MapViewOptions& options, const LiveRequest& request) {
  using Clock = std::chrono::steady_clock;
  // The window is probed before any DDS thread exists (fork).
  const bool window = options.window && !request.no_window && open_window();
  const bool snapshots = !window || request.out_given;
  const std::string dir = request.out_dir.empty() ? options.snapshot_dir : request.out_dir;
  const std::string latest = (std::filesystem::path(dir) / "map_latest.png").string();

  Shared shared(options.trajectory_min_step_m);
  dds::Participant participant(options.dds, "map_view");
  dds::Reader<msg::MapState> maps(participant, [&](const msg::MapState& m) {
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.changed = shared.builder.add(m) || shared.changed;
  });
  dds::Reader<msg::GroundTruth> truth(participant, [&](const msg::GroundTruth& g) {
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.builder.add(g);
    shared.changed = true;
  });
  dds::Reader<msg::OptimisedMap> optimised(participant, [&](const msg::OptimisedMap& m) {
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.changed = shared.builder.add(m) || shared.changed;
  });
  dds::Reader<msg::FleetMap> fleet(participant, [&](const msg::FleetMap& m) {
    std::lock_guard<std::mutex> lock(shared.mutex);
    shared.changed = shared.builder.add(m) || shared.changed;
  });
  std::fprintf(stderr, "map_view: listening on DDS domain %d; %s%s%s\n", options.dds.domain_id,
               window ? "window" : "no window", snapshots ? ", snapshots to " : "", snapshots ? latest.c_str() : "");

  RenderOptions render = options.render;
  WorldBox view;  // only grows: the map does not jump back and forth
  MapViewState state;
  bool have_state = false;
  std::size_t snapshots_written = 0;
  const auto period = std::chrono::duration<double>(options.snapshot_period_s);
  const auto window_period = std::chrono::duration<double>(std::min(options.snapshot_period_s, 0.2));
  auto next_snapshot = Clock::now() + std::chrono::duration_cast<Clock::duration>(period);
  auto next_draw = Clock::now();
  cv::Mat image;
  std::size_t version = 0;        // of `image`
  std::size_t shown_version = 0;  // in the window

  auto redraw = [&]() -> bool {
    {
      std::lock_guard<std::mutex> lock(shared.mutex);
      if (!shared.changed && !image.empty()) return false;
      shared.changed = false;
      state = shared.builder.state();
      have_state = shared.builder.map_states() > 0 || shared.builder.ground_truths() > 0 ||
                   shared.builder.optimised_maps() > 0;
    }
    view.extend(content_bounds(state, render.sigma_scale, render.ground_truth));
    render.view = view;
    if (!have_state) state.caption = "waiting for pixyslam/map_state ...";
    image = render_map(state, render);
    ++version;
    return true;
  };
  auto snapshot = [&] {
    write_png(latest, image);
    ++snapshots_written;
  };

  while (!app::StopSignal::requested()) {
    const auto now = Clock::now();
    if (window && now >= next_draw) {
      redraw();
      if (version != shown_version) {
        cv::imshow(kWindow, image);
        shown_version = version;
      }
      next_draw = now + std::chrono::duration_cast<Clock::duration>(window_period);
    }
    if (snapshots && now >= next_snapshot) {
      const bool changed = redraw();
      if (changed || snapshots_written == 0) snapshot();
      next_snapshot = now + std::chrono::duration_cast<Clock::duration>(period);
    }
    if (window) {
      if (!window_alive(30)) break;
    } else {
      app::StopSignal::wait_for(std::chrono::milliseconds(50));
    }
  }
  if (snapshots) {
    redraw();
    snapshot();
  }
  if (window) cv::destroyAllWindows();
  std::size_t dropped = 0;
  {
    std::lock_guard<std::mutex> lock(shared.mutex);  // the readers still run
    dropped = shared.builder.robots_evicted();
  }
  std::fprintf(stderr,
               "map_view: stopped; %llu map states, %llu ground-truth messages, %llu optimised maps received "
               "(%zu robots dropped for newer ones past %zu)%s%s\n",
               static_cast<unsigned long long>(maps.received()), static_cast<unsigned long long>(truth.received()),
               static_cast<unsigned long long>(optimised.received()), dropped,
               FleetViewBuilder::kMaxRobots, snapshots ? "; last snapshot " : "",
               snapshots ? latest.c_str() : "");
  return 0;
}

}  // namespace pixyslam::map_view
