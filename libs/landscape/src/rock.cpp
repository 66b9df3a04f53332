// rock.cpp — tilted beds of varying strength (rock.hpp).
#include <orogen/landscape/rock.hpp>

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <numbers>
#include <cstdlib>
#include <limits>

namespace orogen::landscape {

namespace {

/// The quintic fade 6t⁵ − 15t⁴ + 10t³: blends lattice values smoothly to the second derivative (so the
/// folded beds have no creases and a facies has no edge).
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/// Value noise in [-1, 1]: the seed's random values at the integer lattice points, blended by the fade.
double value_noise(double u, double v, std::uint64_t seed, std::uint64_t octave) {
    const double fu = std::floor(u), fv = std::floor(v);
    const auto i = static_cast<std::int64_t>(fu), j = static_cast<std::int64_t>(fv);
    const double a = fade(u - fu), b = fade(v - fv);
    const auto at = [&](std::int64_t di, std::int64_t dj) {
        return random::uniform_in(-1.0, 1.0, seed, octave, std::uint64_t(i + di), std::uint64_t(j + dj));
    };
    const double lo = at(0, 0) + a * (at(1, 0) - at(0, 0)), hi = at(0, 1) + a * (at(1, 1) - at(0, 1));
    return lo + b * (hi - lo);
}

/// Keeps the folds' random values apart from the beds' strengths, which use the seed itself.
constexpr std::uint64_t kFoldSalt = 0x666f6c6473ull;  // "folds"

/// ... and the beds' thicknesses and the faults from the strengths and from each other.
constexpr std::uint64_t kThicknessSalt = 0x746869636bull;  // "thick"
constexpr std::uint64_t kFaultSalt = 0x6661756c7473ull;  // "faults"
constexpr std::uint64_t kBlockSalt = 0x626c6f636bull;  // "block"
constexpr std::uint64_t kFaciesSalt = 0x666163696573ull;  // "facies"

/// Φ⁻¹(p), the standard normal quantile, p in (0, 1): Acklam's rational approximation (relative error
/// below 1.2·10⁻⁹; a strength class is 1/256 wide).
double normal_quantile(double p) {
    constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                            1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
    constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                            6.680131188771972e+01, -1.328068155288572e+01};
    constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                            -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
    constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00, 3.754408661907416e+00};
    constexpr double tail = 0.02425;
    p = std::clamp(p, 1e-12, 1.0 - 1e-12);
    const auto tail_x = [&](double q) {
        return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    };
    if (p < tail) return tail_x(std::sqrt(-2.0 * std::log(p)));
    if (p > 1.0 - tail) return -tail_x(std::sqrt(-2.0 * std::log(1.0 - p)));
    const double q = p - 0.5, r = q * q;
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

/// The strength classes' normal scores: each class's middle, Φ⁻¹((k + 1/2)/kStrengths), and the bounds
/// between them, Φ⁻¹(k/kStrengths) for k = 1 … kStrengths − 1.
/// The class of a score z is the number of bounds at or below it; `first` holds that number at the lower
/// edge of each of kBuckets equal buckets over [−kReach, kReach), so finding it takes a step or two from
/// there rather than a binary search's eight unpredictable branches (a cell's class, every step).
struct NormalScores {
    static constexpr int kBuckets = 2048;
    static constexpr double kReach = 6.0;
    double middle[Beds::kStrengths];
    double bound[Beds::kStrengths - 1];
    int first[kBuckets];

    /// The number of bounds at or below z: std::upper_bound's answer.
    int class_of(double z) const {
        const double t = (z + kReach) * (kBuckets / (2.0 * kReach));
        int k = first[t > 0.0 ? (t < kBuckets - 1 ? int(t) : kBuckets - 1) : 0];
        while (k < Beds::kStrengths - 1 && bound[k] <= z) ++k;
        while (k > 0 && bound[k - 1] > z) --k;  // a bucket's edge rounded past z
        return k;
    }
};
const NormalScores& normal_scores() {
    static const NormalScores scores = [] {
        NormalScores s{};
        for (int k = 0; k < Beds::kStrengths; ++k) s.middle[k] = normal_quantile((k + 0.5) / Beds::kStrengths);
        for (int k = 1; k < Beds::kStrengths; ++k) s.bound[k - 1] = normal_quantile(double(k) / Beds::kStrengths);
        for (int b = 0; b < NormalScores::kBuckets; ++b) {
            const double edge = -NormalScores::kReach + b * (2.0 * NormalScores::kReach / NormalScores::kBuckets);
            s.first[b] = int(std::upper_bound(std::begin(s.bound), std::end(s.bound), edge) - s.bound);
        }
        return s;
    }();
    return scores;
}

/// A facies lattice node's normal score for bed `bed`, from its draw.
double facies_node(std::uint64_t facies_seed, std::int64_t bed, std::int64_t a, std::int64_t b) {
    return normal_quantile(random::uniform(facies_seed, std::uint64_t(bed), std::uint64_t(a), std::uint64_t(b)));
}

/// Where a coordinate (m) lies on the facies lattice: the node below it, the fade t towards the next, and
/// (1 − t)² + t², what the blend's variance shrinks to between the two.
struct LatticeAt {
    std::int64_t node;
    double fade, shrink;
};
LatticeAt lattice_at(const Beds& beds, double x) {
    const double u = x / beds.facies_length, fu = std::floor(u), t = fade(u - fu);
    return {static_cast<std::int64_t>(fu), t, (1.0 - t) * (1.0 - t) + t * t};
}

/// The class of a bed drawn as class k where its facies change it: in normal scores, the bed's own score
/// weighted by √(1 − share²) plus share times a standard normal field along the bed (the lattice nodes'
/// scores n00 … n11 blended by the fades, divided by the blend's standard deviation so the field is
/// standard normal everywhere, not only at the nodes). The sum is standard normal too, so the classes stay
/// evenly spread, as without facies: the facies move strength along a bed, they do not make the rock
/// stronger or weaker on the whole.
inline int facies_class(const Beds& beds, int k, double n00, double n10, double n01, double n11, const LatticeAt& u,
                        const LatticeAt& v) {
    const NormalScores& scores = normal_scores();
    const double lo = n00 + u.fade * (n10 - n00), hi = n01 + u.fade * (n11 - n01);
    const double field = (lo + v.fade * (hi - lo)) / std::sqrt(u.shrink * v.shrink);
    const double w = beds.facies_share;
    const double z = std::sqrt(1.0 - w * w) * scores.middle[k] + w * field;
    return scores.class_of(z);
}

/// The strength class of the bed at height q (m) above the bed surface through the origin, at (x, y) (m).
int class_of(const Beds& beds, double q, double x, double y) {
    const std::int64_t bed = beds.bed_at(q);
    const int k = int(random::below(Beds::kStrengths, beds.seed, std::uint64_t(bed)));
    if (!beds.facies()) return k;
    const LatticeAt u = lattice_at(beds, x), v = lattice_at(beds, y);
    const std::uint64_t s = random::hash(beds.seed, kFaciesSalt);
    const auto node = [&](std::int64_t da, std::int64_t db) { return facies_node(s, bed, u.node + da, v.node + db); };
    return facies_class(beds, k, node(0, 0), node(1, 0), node(0, 1), node(1, 1), u, v);
}

/// One fault: its trace's middle (m), the unit vector along it, its half-length (m) and its throw (m, the
/// far side of the trace (left of the direction) is lifted by half of it, the near side dropped by half).
struct Fault {
    double x = 0.0, y = 0.0, along_x = 1.0, along_y = 0.0, half_length = 0.0, throw_m = 0.0;
};

/// The fault of lattice square (a, b) (squares `fault_spacing` across, a east, b south): its middle
/// anywhere in the square, any strike, 1–3 spacings long, a throw of 1/4 to all of fault_throw.
Fault fault_in(const Beds& beds, std::int64_t a, std::int64_t b) {
    const std::uint64_t s = random::hash(beds.seed, kFaultSalt);
    const auto u = [&](std::uint64_t k) { return random::uniform(s, std::uint64_t(a), std::uint64_t(b), k); };
    const double spacing = beds.fault_spacing, strike = std::numbers::pi * u(2);
    Fault f;
    f.x = (double(a) + u(0)) * spacing;
    f.y = (double(b) + u(1)) * spacing;
    f.along_x = std::cos(strike);
    f.along_y = std::sin(strike);
    f.half_length = spacing * (0.5 + u(3));
    f.throw_m = beds.fault_throw * (0.25 + 0.75 * u(4));
    return f;
}

/// How far a fault lifts the beds at (x, y): ± half its throw on either side of the trace, greatest at its
/// middle and dying away (smoothly, as (1 − r²)²) to nothing at its half-length from the middle.
double fault_lift(const Fault& f, double x, double y) {
    const double dx = x - f.x, dy = y - f.y;
    const double along = dx * f.along_x + dy * f.along_y, across = dy * f.along_x - dx * f.along_y;
    const double r2 = (along * along + across * across) / (f.half_length * f.half_length);
    if (r2 >= 1.0) return 0.0;
    return (across >= 0.0 ? 0.5 : -0.5) * f.throw_m * (1.0 - r2) * (1.0 - r2);
}

/// The faults' lift at (x, y): the sum over the 5 × 5 lattice squares around it (a fault reaches at most
/// 1.5 spacings from its middle, which lies in its square), in one fixed order. `fault_of(a, b)` gives
/// square (a, b)'s fault, so a caller can look them up in a table rather than draw them again.
template <typename FaultOf>
double faults_lift(const Beds& beds, double x, double y, FaultOf&& fault_of) {
    const auto a0 = static_cast<std::int64_t>(std::floor(x / beds.fault_spacing));
    const auto b0 = static_cast<std::int64_t>(std::floor(y / beds.fault_spacing));
    double lift = 0.0;
    for (std::int64_t b = b0 - 2; b <= b0 + 2; ++b)
        for (std::int64_t a = a0 - 2; a <= a0 + 2; ++a) lift += fault_lift(fault_of(a, b), x, y);
    return lift;
}

}  // namespace

double Beds::fold(double x, double y) const {
    if (!folded()) return 0.0;
    // Across the fold axes is along the dip; the axes run along the strike, three times as long. Two
    // octaves: folds of the wavelength, and smaller ones on their limbs at half the height.
    const double across = x * dip_east + y * dip_south, along = -x * dip_south + y * dip_east;
    const double u = across / (0.5 * fold_wavelength), v = along / (1.5 * fold_wavelength);
    const std::uint64_t s = random::hash(seed, kFoldSalt);
    const double f = value_noise(u, v, s, 0) + 0.5 * value_noise(2.0 * u, 2.0 * v, s, 1);
    return fold_amplitude * f / 1.5;
}

double Beds::fault(double x, double y) const {
    if (!faulted()) return 0.0;
    return faults_lift(*this, x, y, [&](std::int64_t a, std::int64_t b) { return fault_in(*this, a, b); });
}

double Beds::offset(double x, double y) const {
    // The bed's base rises towards the dip's opposite and where the folds or the faults lift it: the rock
    // at a given height there lies in a lower bed.
    return dip_slope * (x * dip_east + y * dip_south) - fold(x, y) - fault(x, y);
}

double Beds::bed_base(std::int64_t k) const {
    if (!(thickness_spread > 0.0)) return thickness * double(k);
    const std::uint64_t s = random::hash(seed, kThicknessSalt);
    return thickness * (double(k) + thickness_spread * (random::uniform(s, std::uint64_t(k)) - 0.5));
}

std::int64_t Beds::bed_at(double q) const {
    // A height that is not finite (the run reports it, naming the node and step) or beyond any bed index
    // lies in bed 0 rather than in an undefined cast.
    const double index = std::floor(q / thickness);
    if (!(std::abs(index) < 0x1p62)) return 0;
    auto bed = static_cast<std::int64_t>(index);
    if (thickness_spread > 0.0) {
        // Bed k's base is within half a thickness of k·thickness, so q lies in bed k − 1, k or k + 1, and
        // two bases tell which.
        if (q < bed_base(bed)) --bed;
        else if (q >= bed_base(bed + 1)) ++bed;
    }
    return bed;
}

int Beds::bed_class(double zeta, double x, double y) const {
    if (!layered()) return kStrengths / 2;
    // q is the height above the bed surface through the origin.
    return class_of(*this, zeta + offset(x, y), x, y);
}

double Beds::strength(double zeta, double x, double y) const {
    return (bed_class(zeta, x, y) + 0.5) / double(kStrengths);
}

double Beds::landslide_slope(double s) const {
    constexpr double lo = 5.0 * std::numbers::pi / 180.0, hi = 80.0 * std::numbers::pi / 180.0;
    return std::tan(std::clamp(angle + angle_spread * (2.0 * s - 1.0), lo, hi));
}

double Beds::erodibility_factor(double s) const { return std::pow(erodibility_contrast, 0.5 - s); }

void bed_offsets(const Beds& beds, const CellBlock& block, std::vector<double>& offsets) {
    const std::size_t count = block.count;
    const int width = block.width, x0 = block.x0, y0 = block.y0;
    const double cell = block.cell;
    offsets.resize(beds.layered() ? count : 0);
    if (!beds.layered()) return;
    // The faults of every lattice square within reach of the block, drawn once (Beds::fault draws the 25
    // around a point each time it is asked); faults_lift adds them up in the same order either way.
    std::vector<Fault> table;
    std::int64_t a_lo = 0, b_lo = 0, a_count = 0;
    if (beds.faulted()) {
        const int height = int(count / std::size_t(width));
        const auto square = [&](int c) { return static_cast<std::int64_t>(std::floor(c * cell / beds.fault_spacing)); };
        a_lo = square(x0) - 2, b_lo = square(y0) - 2;
        a_count = square(x0 + width - 1) + 3 - a_lo;
        const std::int64_t b_count = square(y0 + height - 1) + 3 - b_lo;
        table.resize(std::size_t(a_count * b_count));
        for (std::int64_t b = 0; b < b_count; ++b)
            for (std::int64_t a = 0; a < a_count; ++a)
                table[std::size_t(b * a_count + a)] = fault_in(beds, a_lo + a, b_lo + b);
    }
    const auto fault_of = [&](std::int64_t a, std::int64_t b) -> const Fault& {
        return table[std::size_t((b - b_lo) * a_count + (a - a_lo))];
    };
    parallel_for(0, std::int64_t(count), 1 << 14, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e; ++i) {
            const double x = double(x0 + int(i % width)) * cell, y = double(y0 + int(i / width)) * cell;
            double offset = beds.dip_slope * (x * beds.dip_east + y * beds.dip_south) - beds.fold(x, y);
            if (beds.faulted()) offset -= faults_lift(beds, x, y, fault_of);
            offsets[std::size_t(i)] = offset;
        }
    });
}

namespace {

constexpr std::int64_t kNoKey = std::numeric_limits<std::int64_t>::min();  // a memo entry never recalled

/// The beds the cells lie in this step, from the lowest to the highest, with one more each side: their
/// bases and classes drawn once into a table rather than hashed per cell (bed_at and class_of's own
/// expressions, so the same bits). Empty when the rock is not layered, or when the heights span more than
/// kMaxBeds beds or are not finite: then each cell falls back on class_of.
struct BedTable {
    std::int64_t first = 0;
    std::vector<double> base;
    std::vector<int> klass;
};

BedTable bed_table(const Beds& beds, const CellBlock& block, const RockInputs& at) {
    BedTable table;
    if (!beds.layered()) return table;
    constexpr std::int64_t kMaxBeds = std::int64_t(1) << 20;
    const std::size_t count = block.count;
    // The range of q, by blocks on every thread (min and max: the same whatever the order).
    constexpr std::int64_t kBlock = 1 << 16;
    const std::int64_t blocks = (std::int64_t(count) + kBlock - 1) / kBlock;
    std::vector<double> block_lo(static_cast<std::size_t>(blocks)), block_hi(static_cast<std::size_t>(blocks));
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) {
            double l = std::numeric_limits<double>::infinity(), h = -l;
            const std::size_t e = std::min(count, std::size_t((b + 1) * kBlock));
            for (std::size_t i = std::size_t(b * kBlock); i < e; ++i) {
                const double q = (at.heights[i] - at.uplifted[i]) + at.offsets[i];
                l = std::min(l, q), h = std::max(h, q);
            }
            block_lo[std::size_t(b)] = l, block_hi[std::size_t(b)] = h;
        }
    });
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::int64_t b = 0; b < blocks; ++b)
        lo = std::min(lo, block_lo[std::size_t(b)]), hi = std::max(hi, block_hi[std::size_t(b)]);
    const double thickness = beds.thickness;
    if (!(lo <= hi && (hi - lo) / thickness < double(kMaxBeds))) return table;
    table.first = static_cast<std::int64_t>(std::floor(lo / thickness)) - 1;
    const std::int64_t beds_in = static_cast<std::int64_t>(std::floor(hi / thickness)) + 2 - table.first + 1;
    table.base.resize(std::size_t(beds_in));
    table.klass.resize(std::size_t(beds_in));
    for (std::int64_t j = 0; j < beds_in; ++j) {
        table.base[std::size_t(j)] = beds.bed_base(table.first + j);
        table.klass[std::size_t(j)] = int(random::below(Beds::kStrengths, beds.seed, std::uint64_t(table.first + j)));
    }
    return table;
}

/// With facies, each tabled bed's draws at the corners of the lattice cells the block covers (class_of's
/// draws), and each column's and row of cells' place on the lattice. Off (`on` false) when the table
/// would hold more than a few corners per cell (many thin beds, a short facies length): then each cell
/// draws its own corners (class_of), which costs less than drawing them all.
struct FaciesTable {
    bool on = false;
    std::vector<double> corner;
    std::vector<LatticeAt> column_at, row_at;
    std::int64_t a_lo = 0, b_lo = 0, a_count = 0, b_count = 0;
};

FaciesTable facies_table(const Beds& beds, const CellBlock& block, const BedTable& bed_table) {
    FaciesTable t;
    if (!beds.facies() || bed_table.base.empty()) return t;
    const int rows = int(block.count / std::size_t(block.width));
    for (int c = 0; c < block.width; ++c) t.column_at.push_back(lattice_at(beds, double(block.x0 + c) * block.cell));
    for (int r = 0; r < rows; ++r) t.row_at.push_back(lattice_at(beds, double(block.y0 + r) * block.cell));
    t.a_lo = t.column_at.front().node, t.b_lo = t.row_at.front().node;
    t.a_count = t.column_at.back().node + 2 - t.a_lo, t.b_count = t.row_at.back().node + 2 - t.b_lo;
    const std::size_t bed_count = bed_table.base.size();
    t.on = double(bed_count) * double(t.a_count) * double(t.b_count) <= 4.0 * double(block.count) + 65536.0;
    if (!t.on) return t;
    t.corner.resize(bed_count * std::size_t(t.a_count * t.b_count));
    const std::uint64_t s = random::hash(beds.seed, kFaciesSalt);
    // Each corner is its own draw: the rows of corners (a bed's row bb) in parallel, the same bits.
    parallel_for(0, std::int64_t(bed_count) * t.b_count, 16, [&](std::int64_t r0, std::int64_t r1) {
        for (std::int64_t r = r0; r < r1; ++r) {
            const std::int64_t j = r / t.b_count, bb = r % t.b_count;
            for (std::int64_t a = 0; a < t.a_count; ++a)
                t.corner[std::size_t(r) * std::size_t(t.a_count) + std::size_t(a)] =
                    facies_node(s, bed_table.first + j, t.a_lo + a, t.b_lo + bb);
        }
    });
    return t;
}

/// One call of rock_at: what it knows before the cells, for the loop over them (rock_of_cells).
struct RockPass {
    const Beds& beds;
    const CellBlock& block;
    const RockInputs& at;
    const BedTable& tabled;
    const FaciesTable& facies;
    bool layered, blocky, vary_slope, vary_k, recall;
    std::int64_t* keys;  // the memo's, or null
    double slope_of[Beds::kStrengths], factor_of[Beds::kStrengths];  // by strength class: a tan and a pow each
    double* slopes;
    double* factors;
};

/// The cell's bed (from the table when it lies in it: bed_at's answer); `j` its row of the table and
/// `in_table` whether it has one.
std::int64_t bed_of(const RockPass& p, double q, std::size_t& j, bool& in_table) {
    const BedTable& t = p.tabled;
    const std::int64_t last = t.first + std::int64_t(t.base.size()) - 1;
    const double index = std::floor(q / p.beds.thickness);
    in_table = index > double(t.first) && index < double(last) && (p.facies.on || !p.beds.facies());
    if (!in_table) return p.beds.bed_at(q);
    j = std::size_t(static_cast<std::int64_t>(index) - t.first);
    if (p.beds.thickness_spread > 0.0) {
        if (q < t.base[j]) --j;
        else if (q >= t.base[j + 1]) ++j;
    }
    return t.first + std::int64_t(j);
}

/// Cells [b, e) of the pass: each one's class, then its slope (with its joint block) and factor.
void rock_of_cells(const RockPass& p, std::int64_t b, std::int64_t e) {
    const Beds& beds = p.beds;
    const int width = p.block.width, x0 = p.block.x0, y0 = p.block.y0;
    const double cell = p.block.cell;
    // The joint blocks: one per cell and cell-deep slice of rock height, keyed by the cell's place in the
    // whole grid (the same on any tiling). No block stands steeper than the landslide angles' 80°.
    const std::uint64_t block_seed = random::hash(beds.seed, kBlockSalt);
    const double steepest = std::tan(80.0 * std::numbers::pi / 180.0);
    for (std::int64_t i = b; i < e; ++i) {
        const double zeta = p.at.heights[i] - p.at.uplifted[i];
        const double q = p.layered ? zeta + p.at.offsets[i] : 0.0;
        std::size_t j = 0;
        bool tabled = false;
        const std::int64_t bed = p.layered ? bed_of(p, q, j, tabled) : 0;
        double slice = 0.0;
        std::int64_t block_key = 0;
        if (p.blocky) {
            slice = std::floor(zeta / cell);
            block_key = std::abs(slice) < 0x1p62 ? static_cast<std::int64_t>(slice) : 0;
        }
        // The memo's key: the bed (32 bits), the block slice (24) and the bed's class here (8), when the bed
        // and slice fit and the height is finite. The same bed keeps its class (its facies do not change
        // with height); a new slice draws only its block again.
        static_assert(Beds::kStrengths <= 256, "a class in the key's 8 bits");
        constexpr std::int64_t kBedFits = std::int64_t(1) << 31, kSliceFits = std::int64_t(1) << 23;
        std::int64_t* const keys = p.keys;
        const bool keyed = keys && std::isfinite(zeta) && std::isfinite(q) && bed > -kBedFits && bed < kBedFits &&
            block_key > -kSliceFits && block_key < kSliceFits;
        const std::uint64_t place =
            keyed ? (std::uint64_t(bed) << 32) | (std::uint64_t(std::uint32_t(block_key) & 0xffffffu) << 8) : 0;
        const bool same_bed = keyed && p.recall && keys[i] != kNoKey && (std::uint64_t(keys[i]) >> 32) == (place >> 32);
        if (same_bed && (std::uint64_t(keys[i]) & ~std::uint64_t(0xff)) == place) continue;  // the same rock
        int k = Beds::kStrengths / 2;
        if (same_bed) {
            k = int(std::uint64_t(keys[i]) & 0xffu);
        } else if (p.layered) {
            // In the table, unless its facies have no table of corners; otherwise (a height outside the
            // table, many corners) the cell's bed and facies are drawn directly.
            if (tabled) {
                k = p.tabled.klass[j];
                if (p.facies.on) {
                    const FaciesTable& f = p.facies;
                    const LatticeAt& u = f.column_at[std::size_t(i % width)];
                    const LatticeAt& v = f.row_at[std::size_t(i / width)];
                    const double* n0 = f.corner.data() +
                        (j * std::size_t(f.b_count) + std::size_t(v.node - f.b_lo)) * std::size_t(f.a_count) +
                        std::size_t(u.node - f.a_lo);
                    const double* n1 = n0 + f.a_count;
                    k = facies_class(beds, k, n0[0], n0[1], n1[0], n1[1], u, v);
                }
            } else {
                k = class_of(beds, q, double(x0 + int(i % width)) * cell, double(y0 + int(i / width)) * cell);
            }
        }
        if (keys) keys[i] = keyed ? std::int64_t(place | std::uint64_t(k)) : kNoKey;
        if (p.vary_slope) {
            double slope = p.slope_of[k];
            if (p.blocky) {
                const double u = random::uniform(block_seed, std::uint64_t(x0 + int(i % width)),
                                                 std::uint64_t(y0 + int(i / width)), std::uint64_t(block_key));
                slope = std::min(slope * (1.0 + beds.block_spread * u), steepest);
            }
            p.slopes[std::size_t(i)] = slope;
        }
        if (p.vary_k) p.factors[std::size_t(i)] = p.factor_of[k];
    }
}

}  // namespace

void rock_at(const Beds& beds, const CellBlock& block, const RockInputs& at, std::vector<double>& slopes,
             std::vector<double>& factors, RockMemo* memo) {
    const std::size_t count = block.count;
    const bool layered = beds.layered();
    const bool blocky = beds.angle > 0.0 && beds.block_spread > 0.0;
    const bool vary_slope = (layered && beds.angle > 0.0 && beds.angle_spread > 0.0) || blocky;
    const bool vary_k = layered && beds.erodibility_contrast != 1.0;
    // The memo holds for these arrays only if they already hold a value for every cell it names.
    const bool recall = memo && memo->key.size() == count && slopes.size() == (vary_slope ? count : 0) &&
        factors.size() == (vary_k ? count : 0);
    slopes.resize(vary_slope ? count : 0);
    factors.resize(vary_k ? count : 0);
    if (!vary_slope && !vary_k) return;
    if (memo && !recall) memo->key.assign(count, kNoKey);
    const BedTable tabled = bed_table(beds, block, at);
    const FaciesTable facies = facies_table(beds, block, tabled);
    RockPass pass{beds,
                  block,
                  at,
                  tabled,
                  facies,
                  layered,
                  blocky,
                  vary_slope,
                  vary_k,
                  recall,
                  memo ? memo->key.data() : nullptr,
                  {},
                  {},
                  slopes.data(),
                  factors.data()};
    // A bed's strength is one of kStrengths classes: the slopes and factors come from a table (a tan and a
    // pow per class, not per cell and step).
    for (int k = 0; k < Beds::kStrengths; ++k) {
        const double s = (k + 0.5) / double(Beds::kStrengths);
        pass.slope_of[k] = beds.landslide_slope(s);
        pass.factor_of[k] = beds.erodibility_factor(s);
    }
    parallel_for(0, std::int64_t(count), 1 << 14, [&](std::int64_t b, std::int64_t e) { rock_of_cells(pass, b, e); });
}

}  // namespace orogen::landscape
