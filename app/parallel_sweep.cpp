// A twin sweep on several cores; see parallel_sweep.hpp.
#include "app/parallel_sweep.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "app/sweep_run.hpp"

namespace synbench::app {
namespace {

// What a job tells the store's owner.
struct Message {
  enum class Kind { point, event, done };
  Kind kind = Kind::point;
  std::size_t job = 0;
  std::size_t index = 0;        // point
  bench::PointRecord record;    // point
  std::string event_kind, text; // event; done: the engine's error
  double bench_s = 0;           // point, done: the job's bench time so far
  bench::SweepState state = bench::SweepState::completed;  // done
  std::optional<std::string> alarm;                        // done
};

class Mailbox {
 public:
  void post(Message m) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(std::move(m));
    }
    ready_.notify_one();
  }
  // Everything posted so far, after waiting up to `wait` for the first.
  std::deque<Message> take(std::chrono::milliseconds wait) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, wait, [this] { return !queue_.empty(); });
    std::deque<Message> out;
    out.swap(queue_);
    return out;
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Message> queue_;
};

// A job's engine sink: its points and events go to the store's owner, nothing is written here.
class JobSink final : public bench::SweepSink {
 public:
  JobSink(Mailbox& box, std::size_t job) : box_(box), job_(job) {}
  std::error_code store_point(std::size_t index, const bench::PointRecord& record) override {
    Message m;
    m.job = job_;
    m.index = index;
    m.record = record;
    m.bench_s = bench_s_;
    box_.post(std::move(m));
    return {};
  }
  void event(const std::string& kind, const std::string& message) override {
    Message m;
    m.kind = Message::Kind::event;
    m.job = job_;
    m.event_kind = kind;
    m.text = message;
    box_.post(std::move(m));
  }
  void progress(const bench::SweepProgress& p) override { bench_s_ = p.bench_elapsed_s; }

 private:
  Mailbox& box_;
  std::size_t job_;
  double bench_s_ = 0;
};

// One job, on its own thread: its twin, supervisor and engine live and die here.
void run_job(std::size_t job, std::size_t jobs, const bench::SweepPlan& plan,
             const std::map<std::size_t, bench::PointRecord>& stored, const ParallelSweepOptions& options,
             const std::atomic<bool>& stop, Mailbox& box) {
  JobSink sink(box, job);
  Message done;
  done.kind = Message::Kind::done;
  done.job = job;
  try {
    auto backend = options.make_backend();
    const BenchDescription& bench = backend->description();
    // As SweepRun: the stricter of the bench's and the plan's limits.
    bench::SafetySupervisor supervisor(backend->devices(), bench::stricter(bench.limits, bench::safety_limits(plan)),
                                       [&sink](const std::string& kind, const std::string& m) { sink.event(kind, m); });
    bench::SweepEngine engine(backend->devices(), supervisor, plan, stored, sink, options.calibration);
    engine.keep_groups(job, jobs);
    done.bench_s = run_to_end(*backend, supervisor, engine, bench.poll_period_s, [&stop] { return stop.load(); });
    done.state = engine.state();
    done.text = engine.error();
    if (supervisor.alarm()) done.alarm = supervisor.alarm()->detail;
  } catch (const std::exception& e) {
    done.state = bench::SweepState::faulted;
    done.text = e.what();
  }
  box.post(std::move(done));
}

}  // namespace

ParallelSweepResult run_parallel_sweep(db::Store& store, std::int64_t id, const bench::SweepPlan& plan,
                                       const std::map<std::size_t, bench::PointRecord>& stored,
                                       const ParallelSweepOptions& options) {
  ParallelSweepResult result;
  const std::size_t jobs = std::max<std::size_t>(1, options.jobs);
  const bool sparse = plan.mode == bench::SweepMode::adaptive;
  if (auto r = store.set_sweep_state(id, db::SweepState::running); !r) {
    result.state = db::SweepState::faulted;
    result.error = r.error().message;
    return result;
  }

  Mailbox box;
  std::atomic<bool> stop{false};
  std::vector<std::thread> threads;
  threads.reserve(jobs);
  for (std::size_t k = 0; k < jobs; ++k)
    threads.emplace_back(run_job, k, jobs, std::cref(plan), std::cref(stored), std::cref(options), std::cref(stop),
                         std::ref(box));

  // The store's owner. A point is written once no running job can still measure a lower one:
  // each job measures its points in increasing order, so a job whose last point is above it, or
  // that has ended, never will.
  std::vector<bool> running(jobs, true);
  std::vector<std::optional<std::size_t>> last(jobs);
  std::vector<double> bench_s(jobs, 0.0);
  std::vector<bench::SweepState> states(jobs, bench::SweepState::completed);
  std::vector<std::string> errors(jobs);
  std::map<std::size_t, std::pair<std::size_t, bench::PointRecord>> waiting;  // index -> (job, record)
  std::optional<std::string> store_error;
  std::size_t ended = 0;
  bool abort_sent = false;
  const std::size_t total = bench::estimate(plan).points;

  const auto write = [&](std::size_t index, const bench::PointRecord& r) {
    if (store_error) return;
    if (auto st = store.insert_point(id, static_cast<std::int64_t>(index), r); !st) {
      store_error = st.error().message;
      stop = true;  // as a serial sweep, which faults on a point it cannot store
      return;
    }
    ++result.written;
    if (options.observer) options.observer->store_point(index, r);
  };
  const auto writable = [&](std::size_t index, std::size_t job) {
    for (std::size_t k = 0; k < jobs; ++k)
      if (k != job && running[k] && (!last[k] || *last[k] < index)) return false;
    return true;
  };

  while (ended < jobs) {
    std::deque<Message> messages = box.take(std::chrono::milliseconds(20));
    if (!abort_sent && options.interrupted && options.interrupted()) {
      abort_sent = true;
      stop = true;
      if (options.on_abort) options.on_abort();
    }
    for (Message& m : messages) {
      switch (m.kind) {
        case Message::Kind::point:
          last[m.job] = m.index;
          bench_s[m.job] = m.bench_s;
          waiting.emplace(m.index, std::make_pair(m.job, std::move(m.record)));
          break;
        case Message::Kind::event:
          (void)store.add_event(id, sweep_event_kind(m.event_kind), m.text);
          if (options.observer) options.observer->event(m.event_kind, m.text);
          break;
        case Message::Kind::done:
          running[m.job] = false;
          ++ended;
          bench_s[m.job] = m.bench_s;
          states[m.job] = m.state;
          errors[m.job] = m.text;
          if (m.alarm && !result.alarm) result.alarm = m.alarm;
          if (m.state == bench::SweepState::faulted) stop = true;  // the sweep ends as a serial one would
          break;
      }
    }
    while (!waiting.empty() && writable(waiting.begin()->first, waiting.begin()->second.first)) {
      write(waiting.begin()->first, waiting.begin()->second.second);
      waiting.erase(waiting.begin());
    }
    if (options.observer && !messages.empty()) {
      bench::SweepProgress p;
      p.done = stored.size() + result.written + waiting.size();
      p.total = std::max(total, p.done);
      for (double s : bench_s) p.bench_elapsed_s += s;
      p.state = stop ? bench::SweepState::stopping : bench::SweepState::running;
      options.observer->progress(p);
    }
  }
  for (auto& t : threads) t.join();
  for (auto& [index, w] : waiting) write(index, w.second);  // every job has ended: the rest, in order

  result.bench_s = *std::max_element(bench_s.begin(), bench_s.end());
  const auto faulted = std::find(states.begin(), states.end(), bench::SweepState::faulted);
  if (faulted != states.end()) {
    result.state = db::SweepState::faulted;
    result.error = errors[static_cast<std::size_t>(faulted - states.begin())];
  } else if (store_error) {
    result.state = db::SweepState::faulted;
    result.error = *store_error;
  } else if (std::find(states.begin(), states.end(), bench::SweepState::aborted) != states.end()) {
    result.state = db::SweepState::aborted;
  }
  if (store_error && result.error != *store_error) result.error += "; " + *store_error;
  const std::optional<std::string> error = result.error.empty() ? std::nullopt : std::optional(result.error);
  if (auto r = store.set_sweep_state(id, result.state, error, sparse); !r) {
    result.error += (result.error.empty() ? "" : "; ") + std::string("recording the final state: ") + r.error().message;
  }
  return result;
}

}  // namespace synbench::app
