// The persistent thread pool (thread_pool.h): workers started once, tasks skipped on cancel.
#include "common/thread_pool.h"

#include "common/cancel.h"

namespace vf {
namespace {
// Whether this thread is running a parallel_for's task: a parallel_for called from one
// runs its tasks on the spot (the pool runs one parallel_for at a time; waiting for it
// there would wait for ever).
thread_local bool in_task = false;

struct InTask {
    bool was = in_task;
    InTask() { in_task = true; }
    ~InTask() { in_task = was; }
};
}  // namespace

ThreadPool& ThreadPool::instance() {
    static ThreadPool pool;
    return pool;
}

int ThreadPool::hardware_threads() {
    unsigned n = std::thread::hardware_concurrency();
    return n > 0 ? (int)n : 1;
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
}

void ThreadPool::ensure_workers(int count) {
    while ((int)workers_.size() < count) {
        int id = (int)workers_.size() + 1;  // worker 0 is the calling thread
        workers_.emplace_back([this, id] { worker_loop(id); });
    }
}

void ThreadPool::worker_loop(int id) {
    uint64_t seen = 0;
    for (;;) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        if (id >= active_limit_ || job_ == nullptr) continue;
        ++running_;
        const auto* job = job_;
        int n = n_tasks_;
        lock.unlock();
        {
            InTask task;
            for (int t; (t = next_.fetch_add(1)) < n;)
                if (!cancelled()) (*job)(t, id);
        }
        lock.lock();
        if (--running_ == 0) done_.notify_all();
    }
}

void ThreadPool::parallel_for(int n, int threads, const std::function<void(int, int)>& fn) {
    if (n <= 0) return;
    if (threads <= 0) threads = hardware_threads();
    threads = std::min(threads, n);
    if (threads == 1 || in_task) {
        for (int t = 0; t < n && !cancelled(); ++t) fn(t, 0);
        return;
    }
    std::lock_guard<std::mutex> call(call_mutex_);
    {
        std::lock_guard<std::mutex> lock(mutex_);
        ensure_workers(threads - 1);
        job_ = &fn;
        n_tasks_ = n;
        next_ = 0;
        active_limit_ = threads;
        running_ = 0;
        ++generation_;
    }
    wake_.notify_all();
    {
        InTask task;
        for (int t; (t = next_.fetch_add(1)) < n;)
            if (!cancelled()) fn(t, 0);
    }
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return running_ == 0 && next_ >= n; });
    job_ = nullptr;
}

}  // namespace vf
