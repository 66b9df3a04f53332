// Tiling::reduce<T> and exchange<T> (kernel/include/orogen/tiles.hpp) over double and int64, in one process:
// a stand-in Tiling whose gather() hands back the parts of two ranks (this one's and a fixed other's, in rank
// order), so reduce's combining is checked per operator without mpirun, and whose exchange_values() records
// what exchange<T> passed on. The MPI transport itself is checked by tests/mpi (seams equal one process).
#include <orogen/tiles.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace {

using namespace orogen;

orogen::TileSplit two_tiles() {
    orogen::TileSplit s;
    s.grid_width = 8;
    s.grid_height = 4;
    s.rows = 1;
    s.cols = 2;
    s.xs = {0, 4, 8};
    s.ys = {0, 4};
    return s;
}

class TwoRanks final : public Tiling {
public:
    explicit TwoRanks(std::string other) : Tiling(two_tiles(), 0, 1), other_(std::move(other)) {}
    std::vector<std::string> gather(std::string_view bytes, Gather) override { return {std::string(bytes), other_}; }
    std::vector<std::string> send_to_ranks(std::span<const std::string> to_rank) override {
        return {to_rank.front(), other_};
    }
    void share_from_rank0(std::string&) override {}
    std::shared_ptr<Heightmap> scatter_from_rank0(const Heightmap*) override { return nullptr; }
    std::vector<float> fetch_samples(const float*, AxisSamples, AxisSamples) override { return {}; }
    void carry(Toward, std::span<double>, int, const std::function<void(int, int)>&) override {}
    void exchange_values(std::span<void* const> grids, std::size_t value_bytes) override {
        passed.assign(grids.begin(), grids.end());
        passed_bytes = value_bytes;
    }
    std::vector<void*> passed;
    std::size_t passed_bytes = 0;

private:
    std::string other_;
};

template <typename T>
std::string bytes_of(std::vector<T> v) {
    return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

template <typename T>
std::vector<T> reduced(std::vector<T> mine, std::vector<T> other, Tiling::Reduce op) {
    TwoRanks t(bytes_of(other));
    t.reduce(std::span<T>(mine), op);
    return mine;
}

TEST(Tiling, ReduceCombinesEveryRanksValuesWithItsOperatorOverDoubles) {
    const std::vector<double> a{1.5, -2.0, 7.25}, b{0.25, 3.0, -7.25};
    EXPECT_EQ(reduced(a, b, Tiling::Reduce::sum), (std::vector<double>{1.75, 1.0, 0.0}));
    EXPECT_EQ(reduced(a, b, Tiling::Reduce::min), (std::vector<double>{0.25, -2.0, -7.25}));
    EXPECT_EQ(reduced(a, b, Tiling::Reduce::max), (std::vector<double>{1.5, 3.0, 7.25}));
    TwoRanks t(bytes_of(std::vector<double>{2.5}));
    EXPECT_EQ(t.reduce(4.0, Tiling::Reduce::sum), 6.5);  // the one-value form
}

TEST(Tiling, ReduceCombinesEveryRanksValuesWithItsOperatorOverInt64) {
    const std::int64_t big = std::int64_t(1) << 40;  // beyond float and int32: no narrowing on the way
    const std::vector<std::int64_t> a{big + 1, -5, 0}, b{big, 9, -1};
    EXPECT_EQ(reduced(a, b, Tiling::Reduce::sum), (std::vector<std::int64_t>{2 * big + 1, 4, -1}));
    EXPECT_EQ(reduced(a, b, Tiling::Reduce::min), (std::vector<std::int64_t>{big, -5, -1}));
    EXPECT_EQ(reduced(a, b, Tiling::Reduce::max), (std::vector<std::int64_t>{big + 1, 9, 0}));
}

TEST(Tiling, ReduceRefusesRanksThatGiveDifferentCounts) {
    std::vector<double> mine{1.0, 2.0};
    TwoRanks t(bytes_of(std::vector<double>{1.0}));
    EXPECT_THROW(t.reduce(std::span<double>(mine), Tiling::Reduce::sum), Error);
}

TEST(Tiling, ExchangePassesEveryGridWithItsValueSize) {
    TwoRanks t("");
    std::vector<double> d1(24), d2(24);
    std::vector<std::int64_t> i1(24);
    double* doubles[] = {d1.data(), d2.data()};
    t.exchange(std::span<double* const>(doubles));
    EXPECT_EQ(t.passed_bytes, sizeof(double));
    EXPECT_EQ(t.passed, (std::vector<void*>{d1.data(), d2.data()}));
    std::int64_t* ints[] = {i1.data()};
    t.exchange(std::span<std::int64_t* const>(ints));
    EXPECT_EQ(t.passed_bytes, sizeof(std::int64_t));
    EXPECT_EQ(t.passed, (std::vector<void*>{i1.data()}));
}

}  // namespace
