// A persistent pool of worker threads: starting threads on every call costs more than
// the work on small images. parallel_for hands out task indices dynamically.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace vf {

class ThreadPool {
public:
    static ThreadPool& instance();
    // Runs fn(task, worker) for task in [0, n) on up to `threads` workers (0: all cores)
    // and returns when all are done. worker is in [0, threads). Once cancel_requested()
    // (common/cancel.h) is set, the tasks not yet started are skipped. Called from inside
    // a task, it runs its tasks there, one after another (as worker 0).
    void parallel_for(int n, int threads, const std::function<void(int, int)>& fn);
    static int hardware_threads();
    ~ThreadPool();

private:
    void ensure_workers(int count);
    void worker_loop(int id);

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    const std::function<void(int, int)>* job_ = nullptr;
    std::atomic<int> next_{0};
    int n_tasks_ = 0, active_limit_ = 0, running_ = 0;
    uint64_t generation_ = 0;
    bool stop_ = false;
    std::mutex call_mutex_;  // one parallel_for at a time
};

}  // namespace vf
