// neighbourhood.cpp — the cell sort (see neighbourhood.hpp): list the live particles, bound their cells,
// key them, order the keys (radix sort, or merge the few that changed cell), list the occupied cells,
// permute the particle arrays.
#include "neighbourhood.hpp"

#include <orogen/parallel.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <type_traits>

namespace orogen::sph {

namespace {

/// gather3/gather8: one loop per run for all A arrays, copied per block of kSlack floats. With a loop per run
/// and array, the loops' set-up cost more than the copies (runs of ~20).
template <int A>
inline std::size_t gather_runs(const float* const (&from)[A], float* const (&to)[A], const std::uint32_t (*run)[2],
                               int nr) {
    std::size_t k = 0;
    for (int r = 0; r < nr; ++r) {
        const std::size_t j = run[r][0], len = run[r][1] - run[r][0];
        for (std::size_t b = 0; b < len; b += kSlack)
            for (int a = 0; a < A; ++a) {
                float t[kSlack];
                for (std::size_t l = 0; l < kSlack; ++l) t[l] = from[a][j + b + l];
                for (std::size_t l = 0; l < kSlack; ++l) to[a][k + b + l] = t[l];
            }
        k += len;
    }
    return k;
}

}  // namespace

OROGEN_SPH_CLONES
std::size_t gather3(const float* const (&from)[3], float* const (&to)[3], const std::uint32_t (*run)[2], int nr) {
    return gather_runs<3>(from, to, run, nr);
}
OROGEN_SPH_CLONES
std::size_t gather8(const float* const (&from)[8], float* const (&to)[8], const std::uint32_t (*run)[2], int nr) {
    return gather_runs<8>(from, to, run, nr);
}

void Neighbourhood::reserve(std::size_t capacity, float h) {
    cap_ = capacity;
    inv_h_ = 1.0f / h;
    sort_keys_.resize(2 * capacity);
    perm_.resize(capacity);
    perm_tmp_.resize(capacity);
    moved_.resize(capacity);
    cell_key_.resize(capacity);
    cell_start_.resize(capacity + 1);
}

void Neighbourhood::sort(Particles& p, bool keep_fields, double merge_movers_up_to) {
    const std::size_t m = list_live(p);
    if (m == 0) {
        p.n = p.live = 0;
        ncell_ = keyed_ = 0;
        return;
    }
    const std::uint64_t top = bound_cells(p, m);
    std::uint64_t* key = sort_keys_.data();
    std::uint64_t* tkey = sort_keys_.data() + cap_;
    const std::size_t movers = key_particles(p, m, key);
    std::uint32_t* idx = perm_.data();
    std::uint32_t* tidx = perm_tmp_.data();
    if (keyed_ == 0 || double(movers) > merge_movers_up_to * double(m)) {
        radix_sort(key, tkey, idx, tidx, m, 64 - __builtin_clzll(top | 1u));
    } else {
        static_assert(kListBlock == kMoverBlock);  // block_first_ counts the movers per block
        merge_movers(key, tkey, idx, tidx, m, block_first_);
        ++merged_sorts_;
    }
    list_cells(key, m);
    permute_particles(p, idx, m, keep_fields);
}

/// The live particles, in index order, into perm_: counted per block of kListBlock in parallel, each block's
/// first place from those counts, then each block lists its own (the serial loop's list). Returns how many.
std::size_t Neighbourhood::list_live(const Particles& p) {
    const std::size_t n = p.n;
    std::vector<std::size_t>& first = block_first_;
    first.assign(n / kListBlock + 2, 0);
    const auto list_blocks = std::int64_t((n + kListBlock - 1) / kListBlock);
    parallel_for(0, list_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            std::size_t c = 0;
            for (std::size_t i = b * kListBlock; i < std::min(n, (b + 1) * kListBlock); ++i) c += p.alive[i];
            first[b + 1] = c;
        }
    });
    for (std::size_t b = 0; b < std::size_t(list_blocks); ++b) first[b + 1] += first[b];
    parallel_for(0, list_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            std::size_t k = first[b];
            for (std::size_t i = b * kListBlock; i < std::min(n, (b + 1) * kListBlock); ++i)
                if (p.alive[i]) perm_[k++] = std::uint32_t(i);
        }
    });
    return first[std::size_t(list_blocks)];
}

/// The listed particles' bounding box of cells, padded by one cell on every side: its first cell and the
/// key strides. Returns the box's last key.
std::uint64_t Neighbourhood::bound_cells(const Particles& p, std::size_t m) {
    const std::int64_t blocks = (std::int64_t(m) + 4095) / 4096;
    std::vector<std::array<float, 6>> box(static_cast<std::size_t>(blocks));
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t blk = b0; blk < b1; ++blk) {
            std::array<float, 6> bb = {kCellLimit, kCellLimit, kCellLimit, -kCellLimit, -kCellLimit, -kCellLimit};
            const std::size_t lo = std::size_t(blk * 4096), hi = std::min(m, lo + 4096);
            for (std::size_t k = lo; k < hi; ++k) {
                const Vec3& q = p.pos[perm_[k]];
                const float c[3] = {cell_of(q.x), cell_of(q.y), cell_of(q.z)};
                for (int a = 0; a < 3; ++a) {
                    bb[std::size_t(a)] = std::min(bb[std::size_t(a)], c[a]);
                    bb[std::size_t(a) + 3] = std::max(bb[std::size_t(a) + 3], c[a]);
                }
            }
            box[std::size_t(blk)] = bb;
        }
    });
    std::array<float, 6> bb = box[0];
    for (const auto& b : box)
        for (std::size_t a = 0; a < 3; ++a) {
            bb[a] = std::min(bb[a], b[a]);
            bb[a + 3] = std::max(bb[a + 3], b[a + 3]);
        }
    min_cx_ = int(bb[0]) - 1;
    min_cy_ = int(bb[1]) - 1;
    min_cz_ = int(bb[2]) - 1;
    const auto nx = std::uint64_t(int(bb[3]) - min_cx_ + 2), ny = std::uint64_t(int(bb[4]) - min_cy_ + 2),
               nz = std::uint64_t(int(bb[5]) - min_cz_ + 2);
    stride_y_ = nx;
    stride_z_ = nx * ny;
    return nx * ny * nz - 1;
}

/// The keys of the listed particles, and which changed cell since the last sort (moved_; a particle spawned
/// since has no cell yet), counted per block of kListBlock into block_first_ (merge_movers' mv_first). The
/// component arrays still hold every particle's position at that sort, in its order (integrate() writes
/// pos, never them), so the others keep their old order. Returns the movers.
std::size_t Neighbourhood::key_particles(const Particles& p, std::size_t m, std::uint64_t* key) {
    std::vector<std::size_t>& first = block_first_;
    const auto key_blocks = std::int64_t((m + kListBlock - 1) / kListBlock);
    first.assign(std::size_t(key_blocks) + 1, 0);
    parallel_for(0, key_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            std::size_t c = 0;
            for (std::size_t k = b * kListBlock; k < std::min(m, (b + 1) * kListBlock); ++k) {
                const std::size_t i = perm_[k];
                const Vec3& q = p.pos[i];
                const float cx = cell_of(q.x), cy = cell_of(q.y), cz = cell_of(q.z);
                key[k] = std::uint64_t(int(cz) - min_cz_) * stride_z_ + std::uint64_t(int(cy) - min_cy_) * stride_y_ +
                    std::uint64_t(int(cx) - min_cx_);
                const bool mv = i >= keyed_ || cx != cell_of(p.soa[0][i]) || cy != cell_of(p.soa[1][i]) ||
                    cz != cell_of(p.soa[2][i]);
                moved_[k] = mv;
                c += mv;
            }
            first[b + 1] = c;
        }
    });
    for (std::size_t b = 0; b < std::size_t(key_blocks); ++b) first[b + 1] += first[b];
    return first[std::size_t(key_blocks)];
}

/// Stable LSD radix sort of (key, idx) by the low `bits` bits of key: each pass, per-block digit
/// histograms in parallel, their offsets in (digit, block) order, then each block scatters its own
/// keys in order. Blocks of fixed size: the same permutation on any thread count. The result is left
/// in key/idx (the pointers are swapped with the scratch t* as the passes go).
void Neighbourhood::radix_sort(std::uint64_t*& key, std::uint64_t*& tkey, std::uint32_t*& idx, std::uint32_t*& tidx,
                               std::size_t m, int bits) {
    constexpr int kDigit = 11;
    constexpr std::size_t kDigits = std::size_t(1) << kDigit, kBlock = 16384;
    const std::size_t nblocks = (m + kBlock - 1) / kBlock;
    radix_offset_.resize(nblocks * kDigits);
    for (int shift = 0; shift < bits; shift += kDigit) {
        parallel_for(0, std::int64_t(nblocks), 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::uint32_t* count = &radix_offset_[b * kDigits];
                std::fill(count, count + kDigits, 0u);
                for (std::size_t k = b * kBlock; k < std::min(m, (b + 1) * kBlock); ++k)
                    ++count[(key[k] >> shift) & (kDigits - 1)];
            }
        });
        std::uint32_t run = 0;
        for (std::size_t d = 0; d < kDigits; ++d)
            for (std::size_t b = 0; b < nblocks; ++b) {
                const std::uint32_t c = radix_offset_[b * kDigits + d];
                radix_offset_[b * kDigits + d] = run;
                run += c;
            }
        parallel_for(0, std::int64_t(nblocks), 1, [&](std::int64_t b0, std::int64_t b1) {
            for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
                std::uint32_t* cursor = &radix_offset_[b * kDigits];
                for (std::size_t k = b * kBlock; k < std::min(m, (b + 1) * kBlock); ++k) {
                    const std::uint32_t dst = cursor[(key[k] >> shift) & (kDigits - 1)]++;
                    tkey[dst] = key[k];
                    tidx[dst] = idx[k];
                }
            }
        });
        std::swap(key, tkey);
        std::swap(idx, tidx);
    }
}

/// The stable sort of (key, idx) by key when few particles changed cell (`moved`, `movers` of the m):
/// a stable sort orders by (key, idx), idx rising along the list, and the particles that kept their
/// cell are already in that order (the last sort's, less the dead). So they are taken out in order,
/// the movers sorted by (key, idx) on their own, and the two merged: the radix sort's permutation
/// exactly, at a few per cent of the particles' sorting work. Blocks of the kept list merge in
/// parallel, each with the movers between its first key and the next block's (a unique result).
/// `mv_first[b]`: the movers before block b of kBlock entries (mv_first[blocks] = all of them).
void Neighbourhood::merge_movers(std::uint64_t* key, std::uint64_t* tkey, std::uint32_t* idx, std::uint32_t* tidx,
                                 std::size_t m, const std::vector<std::size_t>& mv_first) {
    constexpr std::size_t kBlock = kMoverBlock;
    const std::size_t blocks = (m + kBlock - 1) / kBlock;
    const std::size_t movers = mv_first[blocks];
    mover_list_.resize(movers);
    parallel_for(0, std::int64_t(blocks), 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            std::size_t mk = mv_first[b], sk = b * kBlock - mv_first[b];
            for (std::size_t k = b * kBlock; k < std::min(m, (b + 1) * kBlock); ++k)
                if (moved_[k]) {
                    mover_list_[mk++] = {key[k], idx[k]};
                } else {
                    tkey[sk] = key[k];
                    tidx[sk++] = idx[k];
                }
        }
    });
    std::sort(mover_list_.begin(), mover_list_.end());
    const std::size_t kept = m - movers;
    const std::size_t sblocks = (kept + kBlock - 1) / kBlock;
    const auto movers_before = [&](std::size_t s) -> std::size_t {  // movers ordered before kept entry s
        if (s >= kept) return movers;
        return std::size_t(std::lower_bound(mover_list_.begin(), mover_list_.end(), std::pair{tkey[s], tidx[s]}) -
                           mover_list_.begin());
    };
    parallel_for(0, std::int64_t(sblocks), 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            const std::size_t s0 = b * kBlock, s1 = std::min(kept, s0 + kBlock);
            std::size_t a = b == 0 ? 0 : movers_before(s0);
            const std::size_t a1 = movers_before(s1);
            std::size_t out = s0 + a;
            for (std::size_t s = s0; s < s1; ++s) {
                const std::pair here{tkey[s], tidx[s]};
                for (; a < a1 && mover_list_[a] < here; ++a, ++out) {
                    key[out] = mover_list_[a].first;
                    idx[out] = mover_list_[a].second;
                }
                key[out] = here.first;
                idx[out++] = here.second;
            }
            for (; a < a1; ++a, ++out) {
                key[out] = mover_list_[a].first;
                idx[out] = mover_list_[a].second;
            }
        }
    });
}

/// The occupied cells (where the sorted key changes), found per block of kListBlock keys in parallel as
/// the particle list in list_live: the serial scan's table.
void Neighbourhood::list_cells(const std::uint64_t* key, std::size_t m) {
    std::vector<std::size_t>& first = block_first_;
    const auto key_blocks = std::int64_t((m + kListBlock - 1) / kListBlock);
    first.assign(std::size_t(key_blocks) + 1, 0);
    const auto starts_cell = [&](std::size_t k) { return k == 0 || key[k] != key[k - 1]; };
    parallel_for(0, key_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            std::size_t c = 0;
            for (std::size_t k = b * kListBlock; k < std::min(m, (b + 1) * kListBlock); ++k) c += starts_cell(k);
            first[b + 1] = c;
        }
    });
    for (std::size_t b = 0; b < std::size_t(key_blocks); ++b) first[b + 1] += first[b];
    parallel_for(0, key_blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (auto b = std::size_t(b0); b < std::size_t(b1); ++b) {
            std::size_t c = first[b];
            for (std::size_t k = b * kListBlock; k < std::min(m, (b + 1) * kListBlock); ++k)
                if (starts_cell(k)) {
                    cell_key_[c] = key[k];
                    cell_start_[c++] = std::uint32_t(k);
                }
        }
    });
    ncell_ = first[std::size_t(key_blocks)];
    cell_start_[ncell_] = std::uint32_t(m);
}

/// The particle arrays in the sorted order `idx` (m entries; the dead are dropped).
void Neighbourhood::permute_particles(Particles& p, const std::uint32_t* idx, std::size_t m, bool keep_fields) {
    // Density and pressure are recomputed before every use in a sub-step; only a compaction between
    // steps (end_step) must keep them with their particles for the views and record(). The
    // accelerations are always recomputed before use. The keys are spent: their 16 bytes per particle
    // are the permutation's scratch.
    if (keep_fields) {
        permute(p.density, idx, m);
        permute(p.pterm, idx, m);
    }
    // The other fields in one gather and one write-back (they were 6 permutes of two passes each and a
    // pass for the component arrays): positions and velocities gathered straight into their component
    // arrays (fixed until integrate(): a cell's candidates are then 9 contiguous runs to copy per
    // component), the sediment into the keys' scratch, acidity, age and lifespan into the
    // accelerations' 12 bytes (recomputed by force_pass before integrate() reads them). Within a
    // sub-step the positions and velocities stay in the component arrays only: density_pass,
    // force_pass and integrate() read them there, and integrate() writes the sorted pos and vel
    // (every particle: it and the exception it may end in need no write-back here). After a
    // compaction between steps (keep_fields) they are written back for the views and record().
    auto* sed_tmp = reinterpret_cast<std::byte*>(sort_keys_.data());
    auto* rest_tmp = reinterpret_cast<std::byte*>(p.acc.data());
    static_assert(sizeof(Vec3) == 12 && sizeof(float) + 2 * sizeof(std::int32_t) == 12);
    auto& soa = p.soa;
    parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
        for (auto k = std::size_t(b); k < std::size_t(e); ++k) {
            const std::size_t i = idx[k];
            const Vec3 q = p.pos[i], v = p.vel[i];
            soa[0][k] = q.x;
            soa[1][k] = q.y;
            soa[2][k] = q.z;
            soa[3][k] = v.x;
            soa[4][k] = v.y;
            soa[5][k] = v.z;
            std::memcpy(sed_tmp + 8 * k, &p.sediment[i], 8);
            std::memcpy(rest_tmp + 12 * k, &p.acidity[i], 4);
            std::memcpy(rest_tmp + 12 * k + 4, &p.age[i], 4);
            std::memcpy(rest_tmp + 12 * k + 8, &p.lifespan[i], 4);
        }
    });
    parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
        for (auto k = std::size_t(b); k < std::size_t(e); ++k) {
            if (keep_fields) {
                p.pos[k] = Vec3{soa[0][k], soa[1][k], soa[2][k]};
                p.vel[k] = Vec3{soa[3][k], soa[4][k], soa[5][k]};
            }
            std::memcpy(&p.sediment[k], sed_tmp + 8 * k, 8);
            std::memcpy(&p.acidity[k], rest_tmp + 12 * k, 4);
            std::memcpy(&p.age[k], rest_tmp + 12 * k + 4, 4);
            std::memcpy(&p.lifespan[k], rest_tmp + 12 * k + 8, 4);
            p.alive[k] = 1;
        }
    });
    p.n = m;
    p.live = m;
    keyed_ = m;
}

/// v in the order p (m entries), through the spent keys' scratch.
template <typename T>
void Neighbourhood::permute(std::vector<T>& v, const std::uint32_t* p, std::size_t m) {
    static_assert(sizeof(T) <= 2 * sizeof(std::uint64_t) && std::is_trivially_copyable_v<T>);
    auto* tmp = reinterpret_cast<std::byte*>(sort_keys_.data());
    parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t k = b; k < e; ++k) std::memcpy(tmp + std::size_t(k) * sizeof(T), &v[p[k]], sizeof(T));
    });
    parallel_for(0, std::int64_t(m), 8192, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t k = b; k < e; ++k)
            std::memcpy(&v[std::size_t(k)], tmp + std::size_t(k) * sizeof(T), sizeof(T));
    });
}

}  // namespace orogen::sph
