// orogen/values.hpp — the values that flow between nodes.
//
//   heightmap  float32 elevation on width × height vertices (the thesis's
//              (N+1)×(M+1) vertices of N×M tiles), cell size in metres, plus
//              named float layers of the same size (water, sediment, ...).
//   image      an RGBA frame, 8-bit or float.
//   particles  a time series of particle frames (structure of arrays).
//   plates     plate polygons over time and collision events.
//   series     an ordered sequence of one of the above, each entry with a time
//              (a heightmap time-lapse, a frame sequence), made on demand.
//
// Values are immutable once a node has produced them; a node that changes its
// input works on a copy (NodeContext::take_heightmap gives one cheaply: the
// input itself when no later node reads it).
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace orogen {

enum class ValueType { none, heightmap, image, particles, plates, series };

/// "heightmap", "image", ...
std::string_view to_string(ValueType type);

// ---------------------------------------------------------------- heightmap

/// Elevation in metres on a regular grid of vertices, with named layers.
///
/// Layer names in use by the shipped plugins (units): water (m of water
/// column), sediment (m of suspended material), flow (m/s), eroded (m, net
/// change, negative = removed), hardness (0..1), plate (plate id as float),
/// uplift (m), boundary (0 none, 1 convergent, 2 divergent, 3 transform).
class Heightmap {
public:
    Heightmap() = default;
    /// A flat heightmap of `width` × `height` vertices at `elevation` metres.
    Heightmap(int width, int height, double cell, float elevation = 0.0f);
    /// A heightmap that adopts `heights` (width × height values, row by row, metres) without copying or
    /// zero-filling: for code that fills the elevations itself (a reader, a generator writing each
    /// vertex once). Throws orogen::Error if the size is not width × height.
    Heightmap(int width, int height, double cell, std::vector<float> heights);

    int width() const { return width_; }
    int height() const { return height_; }
    double cell() const { return cell_; }
    std::size_t size() const { return std::size_t(width_) * std::size_t(height_); }

    GridView view() { return {heights_.data(), width_, height_, cell_}; }
    ConstGridView view() const { return {heights_.data(), width_, height_, cell_}; }
    std::vector<float>& heights() { return heights_; }
    const std::vector<float>& heights() const { return heights_; }

    bool has_layer(std::string_view name) const;
    /// The layer `name`, created (filled with `fill`) if it does not exist yet.
    GridView layer(std::string_view name, float fill = 0.0f);
    /// Make `values` (size() values, row by row) the layer `name`, replacing a layer of that name, without
    /// copying or filling. Throws orogen::Error if the size is not size().
    void set_layer(std::string_view name, std::vector<float> values);
    /// The layer `name`; throws orogen::Error naming the existing layers if absent.
    ConstGridView layer(std::string_view name) const;
    void remove_layer(std::string_view name);
    std::vector<std::string> layer_names() const;

private:
    int width_ = 0;
    int height_ = 0;
    double cell_ = 1.0;
    std::vector<float> heights_;
    std::map<std::string, std::vector<float>, std::less<>> layers_;
};

// -------------------------------------------------------------------- image

/// An RGBA frame, rows top to bottom. Exactly one of rgba8 / rgba32f is filled.
struct Image {
    enum class Format { rgba8, rgba32f };
    int width = 0;
    int height = 0;
    Format format = Format::rgba8;
    std::vector<std::uint8_t> rgba8;  ///< width*height*4 bytes, sRGB
    std::vector<float> rgba32f;  ///< width*height*4 floats, linear
};

// ---------------------------------------------------------------- particles

/// One attribute of every particle: `components` floats per particle,
/// interleaved (x0 y0 z0 x1 y1 z1 ... for a 3-component vector).
struct ParticleAttribute {
    int components = 1;
    std::vector<float> data;
};

/// The particles at one instant. Attribute "position" (3 components, metres,
/// x east, y up, z south, origin at the heightmap's vertex (0,0)) always exists;
/// others by convention: "velocity" (3, m/s), "density" (1, kg/m³),
/// "sediment" (1, m³), "age" (1, steps).
struct ParticleFrame {
    double time = 0.0;  ///< seconds since the simulation started
    std::int64_t step = 0;
    std::map<std::string, ParticleAttribute, std::less<>> attributes;
    std::size_t count() const;
};

/// A time series of particle frames.
struct ParticleSeries {
    std::vector<ParticleFrame> frames;
};

// ------------------------------------------------------------------- plates

/// One plate at one instant: a convex polygon (counter-clockwise, metres in
/// heightmap coordinates: x east, y south, origin at vertex (0,0)).
struct PlateState {
    int id = 0;
    std::vector<Point2> polygon;
    Point2 velocity;  ///< m per simulation second
    double density = 1.0;  ///< relative; denser plates subduct
};

struct PlateSnapshot {
    std::int64_t step = 0;
    double time = 0.0;
    std::vector<PlateState> plates;
};

enum class BoundaryKind { convergent = 1, divergent = 2, transform = 3 };

/// A contact between two plates: the segment where they touch, in metres.
struct CollisionEvent {
    std::int64_t step = 0;
    int plate_a = 0;
    int plate_b = 0;
    Point2 a;
    Point2 b;
    BoundaryKind kind = BoundaryKind::convergent;
    double impulse = 0.0;  ///< N·s in simulation units
};

/// A plate simulation's history.
struct PlateHistory {
    double width = 0.0;  ///< extent of the simulated area, metres
    double height = 0.0;
    std::vector<PlateSnapshot> snapshots;
    std::vector<CollisionEvent> collisions;
};

// -------------------------------------------------------------------- value

struct Series;

/// Any value, shared and immutable. Empty (`type() == none`) for nodes that
/// only write files.
class Value {
public:
    Value() = default;
    Value(std::shared_ptr<const Heightmap> v) : v_(std::move(v)) {}
    Value(std::shared_ptr<const Image> v) : v_(std::move(v)) {}
    Value(std::shared_ptr<const ParticleSeries> v) : v_(std::move(v)) {}
    Value(std::shared_ptr<const PlateHistory> v) : v_(std::move(v)) {}
    Value(std::shared_ptr<Heightmap> v) : v_(std::shared_ptr<const Heightmap>(std::move(v))) {}
    Value(std::shared_ptr<Image> v) : v_(std::shared_ptr<const Image>(std::move(v))) {}
    Value(std::shared_ptr<ParticleSeries> v) : v_(std::shared_ptr<const ParticleSeries>(std::move(v))) {}
    Value(std::shared_ptr<PlateHistory> v) : v_(std::shared_ptr<const PlateHistory>(std::move(v))) {}
    Value(std::shared_ptr<const Series> v) : v_(std::move(v)) {}
    Value(std::shared_ptr<Series> v) : v_(std::shared_ptr<const Series>(std::move(v))) {}

    ValueType type() const { return ValueType(v_.index()); }
    explicit operator bool() const { return type() != ValueType::none; }

    /// The held value; throw orogen::Error if it is of another type.
    const std::shared_ptr<const Heightmap>& heightmap() const;
    const std::shared_ptr<const Image>& image() const;
    const std::shared_ptr<const ParticleSeries>& particles() const;
    const std::shared_ptr<const PlateHistory>& plates() const;
    const std::shared_ptr<const Series>& series() const;

private:
    // Order matches ValueType.
    std::variant<std::monostate, std::shared_ptr<const Heightmap>, std::shared_ptr<const Image>,
                 std::shared_ptr<const ParticleSeries>, std::shared_ptr<const PlateHistory>,
                 std::shared_ptr<const Series>>
        v_;
};

// ------------------------------------------------------------------- series

/// An ordered sequence of values of one type — a heightmap time-lapse
/// recorded by an eroder, the frames of a turntable — each with a time.
///
/// Entries are made on demand by `make`, so a consumer (a video encoder, an
/// exporter writing numbered files) pulls them one at a time and never holds
/// them all: a 300-frame 1080p turntable costs one frame of memory, not 300.
/// A producer that already holds its entries (a time-lapse) returns them
/// from `make`; one that computes them (a render) captures what it needs by
/// value (shared_ptrs to its inputs, its parameters).
struct Series {
    ValueType element = ValueType::none;  ///< type of every entry (never series)
    std::vector<double> times;  ///< one per entry, in the producer's clock (seconds, or years)
    /// Makes entry i (0 ≤ i < size()). May be called more than once, in any
    /// order, from one thread at a time; must be deterministic.
    std::function<Value(std::size_t)> make;

    std::size_t size() const { return times.size(); }
    /// make(i), checked: throws orogen::Error if i is out of range or the
    /// entry is not of type `element`.
    Value at(std::size_t i) const;
};

/// A series over values already made (a recorded time-lapse).
std::shared_ptr<Series> series_of(ValueType element, std::vector<double> times, std::vector<Value> entries);

}  // namespace orogen
