// The hub's sampling timer and push messages; see ws_hub.hpp.
#include "server/http/ws_hub.hpp"

#include <boost/asio/post.hpp>

#include "bench/pace.hpp"
#include "server/http/api_routes.hpp"
#include "server/http/ws_session.hpp"

namespace synbench::http {

namespace {

SharedText share(std::string s) { return std::make_shared<const std::string>(std::move(s)); }

}  // namespace

double unix_ms_now() {
  using namespace std::chrono;
  return static_cast<double>(duration_cast<microseconds>(system_clock::now().time_since_epoch()).count()) / 1000.0;
}

std::string telemetry_message(const BenchStatus& s, double sent_unix_ms) {
  synbench::Json j = {{"type", "telemetry"}, {"t_s", s.t_s}, {"sent_unix_ms", sent_unix_ms},
                      {"enabled", s.enabled}, {"phase", phase_name(s.phase)}};
  const synbench::Json null;
  j["speed_rpm"] = s.synrm ? synbench::Json(s.synrm->speed_rpm) : null;
  j["torque_Nm"] = s.load ? synbench::Json(s.load->torque_Nm) : null;  // the load machine's braking torque
  j["im_A"] = s.synrm ? synbench::Json(s.synrm->im_A) : null;
  j["id_A"] = s.synrm ? synbench::Json(s.synrm->id_A) : null;
  j["iq_A"] = s.synrm ? synbench::Json(s.synrm->iq_A) : null;
  j["udc_V"] = s.synrm ? synbench::Json(s.synrm->udc_V) : null;
  // The drive's own estimate of its output power, 1.5 (ud id + uq iq): not a DC-side measurement.
  j["pac_W"] = s.synrm ? synbench::Json(s.synrm->pac_W) : null;
  j["temp_C"] = s.synrm && s.synrm->temp_C ? synbench::Json(*s.synrm->temp_C) : null;
  j["pos_err_deg"] = s.synrm && s.synrm->pos_err_deg ? synbench::Json(*s.synrm->pos_err_deg) : null;
  j["voltage_limited"] = s.synrm ? synbench::Json(s.synrm->voltage_limited) : null;
  j["lock_lost"] = s.synrm ? synbench::Json(s.synrm->lock_lost) : null;
  j["fault"] = s.synrm ? synbench::Json(std::string(drivers::fault_name(s.synrm->fault))) : null;
  // What the bench commands now (a sweep's point, its load ramp, a stop), not the manual setpoints.
  j["cmd_speed_rpm"] = s.commanded.speed_rpm;
  j["cmd_load_Nm"] = s.commanded.load_Nm;
  j["cmd_angle_deg"] = s.commanded.angle_deg;
  return dump_json(j);
}

synbench::Json sweep_json(const BenchStatus& s, std::optional<double> eta_s) {
  const synbench::Json null;
  if (!s.sweep) return {{"type", "sweep"}, {"id", null}, {"state", null}, {"done", 0}, {"total", 0}, {"eta_s", null}};
  return {{"type", "sweep"},        {"id", s.sweep->id},       {"state", s.sweep->state},
          {"done", s.sweep->done},  {"total", s.sweep->total}, {"eta_s", eta_s ? synbench::Json(*eta_s) : null}};
}

std::string state_message(const BenchStatus& s) {
  synbench::Json j = status_json(s);
  j["type"] = "state";
  return dump_json(j);
}

std::string event_message(const BenchEvent& e) {
  return dump_json(synbench::Json{{"type", "event"}, {"seq", e.seq}, {"t_s", e.t_s}, {"kind", e.kind}, {"message", e.message}});
}

WsHub::WsHub(boost::asio::io_context& io, BenchRuntime& bench, const Router& router, Authenticator auth, std::string version,
             WsLimits limits)
    : io_(io), bench_(bench), router_(router), auth_(std::move(auth)), version_(std::move(version)), limits_(limits) {}

void WsHub::start() {
  if (timer_) return;
  timer_ = std::make_unique<boost::asio::steady_timer>(io_);
  start_ = std::chrono::steady_clock::now();
  index_ = 0;
  schedule();
}

void WsHub::stop() { timer_.reset(); }  // a pending wait completes with operation_aborted

void WsHub::schedule() {
  // Absolute deadlines, so the rate does not drift with the handler's own time.
  timer_->expires_at(start_ + kPeriod * static_cast<long>(index_ + 1));
  timer_->async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (ec || !self->timer_) return;
    self->on_tick();
  });
}

void WsHub::join(const std::shared_ptr<WsSession>& session) {
  std::lock_guard lock(mutex_);
  sessions_[session.get()] = session;
}

void WsHub::leave(const WsSession* session) {
  std::lock_guard lock(mutex_);
  sessions_.erase(session);
}

std::size_t WsHub::session_count() const {
  std::lock_guard lock(mutex_);
  return sessions_.size();
}

std::string WsHub::sweep_message(const BenchStatus& s) const {
  std::lock_guard lock(mutex_);
  const bool tracked = s.sweep && s.sweep->id == eta_sweep_id_ && s.sweep->state == "running";
  return dump_json(sweep_json(s, tracked ? eta_s_ : std::nullopt));
}

void WsHub::on_tick() {
  const auto now = std::chrono::steady_clock::now();
  // A late tick (a busy io thread) skips the periods it missed: clients keep their rate in
  // wall time instead of receiving a burst.
  index_ = static_cast<std::uint64_t>((now - start_) / kPeriod);
  schedule();

  std::vector<std::shared_ptr<WsSession>> targets;
  {
    std::lock_guard lock(mutex_);
    targets.reserve(sessions_.size());
    for (const auto& [p, w] : sessions_)
      if (auto sp = w.lock()) targets.push_back(std::move(sp));
  }
  // Without sessions only the change tracking runs (so a later client is not sent history).
  const bool build = !targets.empty();
  const auto snap = bench_.snapshot();  // the bench thread's immutable snapshot
  const BenchStatus& s = snap->status;
  auto tick = std::make_shared<HubTick>();
  tick->index = index_;
  if (build) tick->telemetry = share(telemetry_message(s, unix_ms_now()));

  // Events by sequence number: each once. Those present when the hub starts are history (the
  // state message carries them), not news.
  std::uint64_t max_seq = last_event_seq_;
  for (const BenchEvent& e : s.events) {
    if (build && primed_ && e.seq > last_event_seq_) tick->events.push_back(share(event_message(e)));
    max_seq = std::max(max_seq, e.seq);
  }
  last_event_seq_ = max_seq;
  // A state message whenever what GET /api/bench/status shows changes, telemetry aside: enable,
  // stop, phase, trip, setpoints, mode, sweep state or point, a new event. So a page need not poll.
  const std::string state_key =
      std::to_string(s.enabled) + std::to_string(s.stopping) + phase_name(s.phase) + std::to_string(s.trip.has_value()) +
      std::to_string(s.alarm.has_value()) + std::to_string(s.heartbeats) +
      "|" + std::to_string(s.setpoints.speed_rpm) + "," + std::to_string(s.setpoints.load_Nm) + "," +
      std::to_string(s.setpoints.angle_deg) + "|" + std::string(drivers::name(s.mode.estimator)) +
      (s.sweep && s.sweep->current_index ? std::to_string(*s.sweep->current_index) : std::string()) +
      std::string(drivers::name(s.mode.pwm)) + "|" + (s.sweep ? std::to_string(s.sweep->id) + s.sweep->state : "") + "|" +
      std::to_string(max_seq);
  if (build && primed_ && state_key != last_state_key_) tick->events.push_back(share(state_message(s)));
  last_state_key_ = state_key;

  {
    std::lock_guard lock(mutex_);
    // ETA from the sweep's progress since the hub first saw it running.
    if (s.sweep && s.sweep->state == "running") {
      if (s.sweep->id != eta_sweep_id_) {
        eta_sweep_id_ = s.sweep->id;
        eta_done0_ = s.sweep->done;
        eta_t0_ = now;
        eta_s_.reset();
      } else if (s.sweep->done > eta_done0_) {
        eta_s_ = bench::remaining_s(std::chrono::duration<double>(now - eta_t0_).count(), s.sweep->done - eta_done0_,
                                    s.sweep->done, s.sweep->total);
      }
    }
  }
  std::string sweep_key;
  if (s.sweep) sweep_key = std::to_string(s.sweep->id) + s.sweep->state + std::to_string(s.sweep->done) + "/" + std::to_string(s.sweep->total);
  if (build && primed_ && sweep_key != last_sweep_key_) tick->sweep = share(sweep_message(s));
  last_sweep_key_ = sweep_key;
  primed_ = true;
  if (!build) return;

  std::shared_ptr<const HubTick> shared_tick = std::move(tick);
  for (const auto& session : targets) session->deliver(shared_tick);
}

}  // namespace synbench::http
