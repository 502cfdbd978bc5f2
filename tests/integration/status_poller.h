#pragma once
// Polls the daemon's status over one control connection, as an operator's
// `calibctl status --follow` would but every `interval`, and records how
// long each answer took, per state: the daemon's loop must answer within
// 100 ms throughout a run (planning, moving, solving, committing).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "calibctl/control_client.h"
#include "calibctl/json_value.h"

namespace cdpr::integration {

class StatusPoller {
 public:
  StatusPoller(const std::string& socket, std::chrono::milliseconds interval) {
    thread_ = std::thread([this, socket, interval] {
      calibctl::ControlClient client;
      std::string error, response;
      if (!client.connect(socket, error)) return;
      while (!stop_.load()) {
        const auto sent = std::chrono::steady_clock::now();
        if (!client.request("status", response, error, 60'000)) break;
        const double latency_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - sent).count();
        const auto status = calibctl::JsonValue::parse(response);
        const std::string state = status ? (*status)["state"].string() : "?";
        {
          std::lock_guard lock(mutex_);
          latencies_ms_.push_back(latency_ms);
          double& worst = worst_by_state_ms_[state];
          worst = std::max(worst, latency_ms);
        }
        std::this_thread::sleep_for(interval);
      }
    });
  }
  ~StatusPoller() { stop(); }
  void stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }

  std::size_t count() const { return latencies_ms_.size(); }
  // The q-quantile (0..1) of the latencies [ms]; call after stop().
  double quantile_ms(double q) const {
    if (latencies_ms_.empty()) return 0.0;
    std::vector<double> sorted = latencies_ms_;
    std::sort(sorted.begin(), sorted.end());
    return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
  }
  std::size_t over_ms(double limit_ms) const {
    return static_cast<std::size_t>(std::count_if(latencies_ms_.begin(), latencies_ms_.end(),
                                                  [&](double ms) { return ms > limit_ms; }));
  }
  // "idle 1.2, preflight 3.4, ..." worst latency per state seen [ms].
  std::string worst_by_state() const {
    std::string text;
    for (const auto& [state, ms] : worst_by_state_ms_) {
      text += (text.empty() ? "" : ", ") + state + " " + std::to_string(ms).substr(0, 6);
    }
    return text;
  }

 private:
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::vector<double> latencies_ms_;
  std::map<std::string, double> worst_by_state_ms_;
};

}  // namespace cdpr::integration
