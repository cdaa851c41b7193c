// The greedy region merger of the tracer, moved here from Python (0.06-0.16 s of a
// photo's trace, one heap operation at a time). It keeps the Python merger's every
// choice, so traces stay byte-identical: heap entries ordered as the tuples
// (must, cost, region, version, target, target's version) were, each region's neighbours
// visited in the order a Python dict kept them (insertion order; a key removed and added
// again goes last), and the costs computed with the same double operations in the same
// order (this file is built without floating-point contraction: see CMakeLists.txt).
#include "trace/merge.h"

#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

namespace vf {
namespace {

// A region's neighbours in a Python dict's key order. Short lists are searched in
// place; long ones (a large region may have thousands of neighbours) get an index.
class OrderedNeighbours {
public:
    int size() const { return live_; }

    // visits the neighbours in order; f must not change this list
    template <typename F>
    void each(F f) const {
        for (int32_t k : keys_)
            if (k >= 0) f(k);
    }

    void insert(int32_t n) {  // at the end, unless already present (then it keeps its place)
        if (find(n) >= 0) return;
        keys_.push_back(n);
        ++live_;
        if (indexed_)
            index_[n] = (uint32_t)(keys_.size() - 1);
        else if (keys_.size() > LINEAR)
            reindex();
    }

    void erase(int32_t n) {
        int64_t at = find(n);
        if (at < 0) return;
        keys_[at] = -1;
        --live_;
        if (indexed_) index_.erase(n);
        if (keys_.size() > 2 * (size_t)live_ + LINEAR) compact();
    }

    void clear() {
        keys_.clear();
        keys_.shrink_to_fit();
        index_.clear();
        indexed_ = false;
        live_ = 0;
    }

private:
    static constexpr size_t LINEAR = 32;  // lists up to this long are scanned

    int64_t find(int32_t n) const {
        if (indexed_) {
            auto it = index_.find(n);
            return it == index_.end() ? -1 : (int64_t)it->second;
        }
        for (size_t i = 0; i < keys_.size(); ++i)
            if (keys_[i] == n) return (int64_t)i;
        return -1;
    }

    void compact() {  // drops the erased slots, keeping the order
        size_t w = 0;
        for (int32_t k : keys_)
            if (k >= 0) keys_[w++] = k;
        keys_.resize(w);
        reindex();
    }

    void reindex() {
        index_.clear();
        indexed_ = keys_.size() > LINEAR;
        if (!indexed_) return;
        for (size_t i = 0; i < keys_.size(); ++i)
            if (keys_[i] >= 0) index_[keys_[i]] = (uint32_t)i;
    }

    std::vector<int32_t> keys_;  // -1: erased
    std::unordered_map<int32_t, uint32_t> index_;
    bool indexed_ = false;
    int32_t live_ = 0;
};

struct Entry {
    int must;  // 0: must merge; 1: merges only while over budget
    double cost;
    int64_t region, version, target, target_version;

    // Python's tuple order
    bool operator<(const Entry& o) const {
        if (must != o.must) return must < o.must;
        if (cost != o.cost) return cost < o.cost;
        if (region != o.region) return region < o.region;
        if (version != o.version) return version < o.version;
        if (target != o.target) return target < o.target;
        return target_version < o.target_version;
    }
    bool operator>(const Entry& o) const { return o < *this; }
};

// Python's float ** 2 calls the C library's pow; x * x could differ in the last bit
// where pow is not correctly rounded, so the call is made the same way here (through a
// pointer, which the compiler cannot replace by a multiplication).
double (*volatile library_pow)(double, double) = std::pow;

class Merger {
public:
    explicit Merger(const MergeInput& in)
        : min_area_(in.min_area), area_(in.area, in.area + in.count), sum_(in.sums, in.sums + 3 * in.count),
          thin_(in.thin, in.thin + in.count), small_(in.count), parent_(in.count), alive_(in.count, 1),
          version_(in.count, 0), adj_(in.count), live_(in.count) {
        for (int64_t i = 0; i < in.count; ++i) {
            small_[i] = thin_[i] || area_[i] < min_area_;
            parent_[i] = i;
        }
        // edges sorted by (a, b): each list gets its neighbours in ascending order, as
        // the Python dicts did
        for (int64_t e = 0; e < in.edges; ++e) {
            adj_[in.pairs[2 * e]].insert((int32_t)in.pairs[2 * e + 1]);
            adj_[in.pairs[2 * e + 1]].insert((int32_t)in.pairs[2 * e]);
        }
        for (int64_t i = 0; i < in.count; ++i) push(i);
    }

    void run(int64_t budget) {
        while (!heap_.empty()) {
            const Entry top = heap_.top();
            if (top.must == 1 && live_ <= budget) return;
            heap_.pop();
            const int64_t r = top.region, t = top.target;
            if (!alive_[r]) continue;
            if (top.version != version_[r] || (t >= 0 && (!alive_[t] || top.target_version != version_[t]))) {
                push(r);
                continue;
            }
            if (t < 0) {
                if (live_ == 1) return;  // never drop everything: a lone speck is the whole picture
                drop(r);
            } else {
                merge(r, t, top.cost);
            }
        }
    }

    MergeResult result() const {
        MergeResult out;
        out.parent = parent_;
        out.alive = alive_;
        return out;
    }

private:
    double cost(int64_t r, int64_t t) const {
        const double ar = area_[r], sr = sum_[3 * r], sg = sum_[3 * r + 1], sb = sum_[3 * r + 2];
        if (t < 0)  // dropping an isolated region leaves white showing (composited over white)
            return (library_pow(sr - ar, 2.0) + library_pow(sg - ar, 2.0) + library_pow(sb - ar, 2.0)) / ar;
        const double at = area_[t], tr = sum_[3 * t], tg = sum_[3 * t + 1], tb = sum_[3 * t + 2];
        const double dr = sr / ar - tr / at, dg = sg / ar - tg / at, db = sb / ar - tb / at;
        return ar * at / (ar + at) * (dr * dr + dg * dg + db * db);
    }

    void push(int64_t r) {
        double best = std::numeric_limits<double>::infinity();
        int64_t target = -1;
        adj_[r].each([&](int32_t t) {
            const double c = cost(r, t);
            if (c < best) {
                best = c;
                target = t;
            }
        });
        if (target < 0) best = cost(r, -1);
        // an isolated sliver (a thin line on transparency) is not forced out: only specks are
        const bool must = small_[r] && (target >= 0 || area_[r] < min_area_);
        heap_.push({must ? 0 : 1, best, r, version_[r], target, target >= 0 ? version_[target] : 0});
    }

    void drop(int64_t r) {
        alive_[r] = 0;
        parent_[r] = -1;
        --live_;
    }

    void merge(int64_t r, int64_t t, double merge_cost) {
        // the region with fewer neighbours is folded into the other
        const int64_t keep = adj_[t].size() >= adj_[r].size() ? t : r;
        const int64_t gone = keep == t ? r : t;
        // a sliver joined to a real region is real; two slivers together are still one
        thin_[keep] = thin_[r] && thin_[t];
        area_[keep] += area_[gone];
        for (int k = 0; k < 3; ++k) sum_[3 * keep + k] += sum_[3 * gone + k];
        small_[keep] = thin_[keep] || area_[keep] < min_area_;
        alive_[gone] = 0;
        parent_[gone] = keep;
        --live_;
        OrderedNeighbours& adj_keep = adj_[keep];
        adj_[gone].each([&](int32_t n) {
            if (n == keep) return;
            adj_keep.insert(n);
            adj_[n].erase((int32_t)gone);  // Python: an[keep] = an.get(keep, 0) + an.pop(gone)
            adj_[n].insert((int32_t)keep);
            ++version_[n];
        });
        adj_keep.erase((int32_t)gone);
        adj_[gone].clear();
        ++version_[keep];
        // Every live region keeps one entry in the heap. t's old entry is now stale and
        // gets refreshed when it comes up; r's entry was just used up, so r needs a new
        // one: exact when cheap, else a stale placeholder keyed by this merge's cost.
        if (keep == r) {
            if (adj_keep.size() <= 64)
                push(keep);
            else
                heap_.push({small_[keep] ? 0 : 1, merge_cost, keep, version_[keep] - 1, -1, 0});
        }
    }

    double min_area_;
    std::vector<double> area_, sum_;
    std::vector<uint8_t> thin_, small_;
    std::vector<int64_t> parent_;
    std::vector<uint8_t> alive_;
    std::vector<int64_t> version_;
    std::vector<OrderedNeighbours> adj_;
    int64_t live_;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap_;
};

}  // namespace

MergeResult merge_regions(const MergeInput& in) {
    Merger merger(in);
    merger.run(in.budget);
    return merger.result();
}

}  // namespace vf
