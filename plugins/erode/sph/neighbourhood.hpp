// neighbourhood.hpp — the neighbour search: a cell list with cells of size h, rebuilt every sub-step by
// sorting the particle arrays by cell (sph.hpp describes the scheme), and the walk over the 27 cells around
// a cell as 9 contiguous runs of the sorted arrays.
//
// RowWalker::next runs once per cell and pass and the run helpers once per cell: defined here, inline.
#pragma once

#include "kernels.hpp"
#include "particles.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace orogen::sph {

class Neighbourhood {
public:
    /// Room for `capacity` particles (see Simulation::bytes_per_particle); `h`: the cells' size, m.
    void reserve(std::size_t capacity, float h);

    /// Every sub-step: sort the live particles by cell (dead ones dropped) and
    /// list the occupied cells. A cell's key is linear in the particles'
    /// bounding box of cells, padded by one cell on every side, x fastest: the
    /// cells x−1, x, x+1 of a row are consecutive keys, so each of the 9 rows
    /// around a cell is one contiguous run of particles. Stable LSD radix sort
    /// with ties in the previous order: the order, and with it every
    /// particle's neighbour and summation order, follows from the state alone.
    /// Leaves positions and velocities in sorted order in p.soa (and, if `keep_fields`, in p.pos and p.vel,
    /// with the densities and pressures: see permute_particles). `merge_movers_up_to`: Settings'.
    void sort(Particles& p, bool keep_fields, double merge_movers_up_to);

    std::size_t cells() const { return ncell_; }  ///< occupied cells
    /// The sorted particles of occupied cell c are [cell_begin(c), cell_begin(c + 1)).
    std::uint32_t cell_begin(std::size_t c) const { return cell_start_[c]; }
    /// Sorts that merged the particles which changed cell into the others' order.
    std::int64_t merged_sorts() const { return merged_sorts_; }

    /// The particles in the 9 rows of 3 cells around a cell, as [begin, end)
    /// runs of the sorted arrays, in a fixed order (z, then y; x ascending
    /// within a run), empty rows skipped. Asked for cells in increasing key
    /// order (one task's range), each row's lookup moves forward from where
    /// the previous cell's ended: a binary search only for the first cell or
    /// after a long gap.
    class RowWalker {
    public:
        explicit RowWalker(const Neighbourhood& m) : m_(m) {}
        int next(std::size_t c, std::uint32_t (*run)[2]) {
            const std::uint64_t k = m_.cell_key_[c];
            const std::uint64_t* first = m_.cell_key_.data();
            const std::uint64_t* last = first + m_.ncell_;
            int nr = 0, row = 0;
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy, ++row) {
                    // The box's padding keeps every key of the row within it: no wrap-around.
                    const std::uint64_t mid = k + std::uint64_t(std::int64_t(dz)) * m_.stride_z_ +
                        std::uint64_t(std::int64_t(dy)) * m_.stride_y_;
                    const std::uint64_t* lo = started_ ? at_[row] : first;
                    if (!started_ || (last - lo > 8 && lo[8] < mid - 1)) lo = std::lower_bound(lo, last, mid - 1);
                    else
                        while (lo != last && *lo < mid - 1) ++lo;
                    at_[row] = lo;
                    const std::uint64_t* hi = lo;
                    while (hi != last && *hi <= mid + 1) ++hi;
                    if (lo == hi) continue;
                    run[nr][0] = m_.cell_start_[std::size_t(lo - first)];
                    run[nr][1] = m_.cell_start_[std::size_t(hi - first)];
                    ++nr;
                }
            started_ = true;
            return nr;
        }

    private:
        const Neighbourhood& m_;
        const std::uint64_t* at_[9] = {};
        bool started_ = false;
    };

private:
    static constexpr std::size_t kListBlock = 16384;  // entries per parallel block of the list steps
    static constexpr std::size_t kMoverBlock = 16384;  // entries per parallel block of merge_movers

    /// Cell coordinate (in units of h) of a position in m, clamped so keys fit in 63 bits.
    float cell_of(float x) const { return std::clamp(std::floor(x * inv_h_), -kCellLimit, kCellLimit); }
    static constexpr float kCellLimit = 524288.0f;  // 2^19: cell coordinates are clamped to ±this

    std::size_t list_live(const Particles& p);
    std::uint64_t bound_cells(const Particles& p, std::size_t m);
    std::size_t key_particles(const Particles& p, std::size_t m, std::uint64_t* key);
    void radix_sort(std::uint64_t*& key, std::uint64_t*& tkey, std::uint32_t*& idx, std::uint32_t*& tidx, std::size_t m,
                    int bits);
    void merge_movers(std::uint64_t* key, std::uint64_t* tkey, std::uint32_t* idx, std::uint32_t* tidx, std::size_t m,
                      const std::vector<std::size_t>& mv_first);
    void list_cells(const std::uint64_t* key, std::size_t m);
    void permute_particles(Particles& p, const std::uint32_t* idx, std::size_t m, bool keep_fields);
    template <typename T>
    void permute(std::vector<T>& v, const std::uint32_t* p, std::size_t m);

    std::size_t cap_ = 0;
    float inv_h_ = 0;  // 1/m, cells per m
    // sort_keys holds two key arrays (the radix sort's ping-pong), reused as the permutation's 16 bytes per
    // particle of scratch.
    std::vector<std::uint64_t> sort_keys_;
    std::vector<std::uint32_t> perm_, perm_tmp_;
    std::vector<std::uint8_t> moved_;  // per sorted entry: changed cell since the last sort (merge_movers)
    std::int64_t merged_sorts_ = 0;  // sorts done by merge_movers
    std::size_t keyed_ = 0;  // particles [0, keyed) have a cell from the last sort (in soa)
    std::vector<std::size_t> block_first_;  // the list steps' per-block places
    std::vector<std::uint32_t> radix_offset_;  // radix_sort's histograms
    std::vector<std::pair<std::uint64_t, std::uint32_t>> mover_list_;  // merge_movers' movers
    // `ncell` occupied cells, each with its key and its first particle (cell_start[ncell] = the particles).
    std::vector<std::uint64_t> cell_key_;
    std::vector<std::uint32_t> cell_start_;
    std::size_t ncell_ = 0;
    std::uint64_t stride_y_ = 1, stride_z_ = 1;  // key steps of one cell in y and z (x: 1)
    int min_cx_ = 0, min_cy_ = 0, min_cz_ = 0;  // the padded box's first cell
};

/// Particles in the runs, and that count rounded up to whole kLanes.
inline std::size_t run_total(const std::uint32_t (*run)[2], int nr) {
    std::size_t m = 0;
    for (int r = 0; r < nr; ++r) m += run[r][1] - run[r][0];
    return m;
}
inline std::size_t padded(std::size_t m) { return (m + kLanes - 1) / kLanes * kLanes; }

/// Grow a scratch buffer to at least `m` entries (never shrinks: reused across cells).
inline float* room(std::vector<float>& v, std::size_t m) {
    if (v.size() < m) v.resize(m + m / 2);
    return v.data();
}

/// Gather a cell's candidates: the runs [run[r][0], run[r][1]) of 3 (positions) or 8 (positions,
/// velocities, p/ρ², ρ) source arrays, one run after another, into as many destination arrays. Copies in
/// blocks of kSlack floats: up to kSlack − 1 floats past each run are read and written (see kSlack).
/// Returns the candidates gathered.
std::size_t gather3(const float* const (&from)[3], float* const (&to)[3], const std::uint32_t (*run)[2], int nr);
std::size_t gather8(const float* const (&from)[8], float* const (&to)[8], const std::uint32_t (*run)[2], int nr);

}  // namespace orogen::sph
