// serialise.cpp — values to and from an entry's payload (serialise.hpp), and value_hash.

#include "serialise.hpp"

#include <orogen/error.hpp>

#include <cmath>
#include <memory>
#include <optional>
#include <sys/mman.h>

namespace orogen::cache {

void advise_huge_pages(void* p, std::size_t n) {
    constexpr std::uintptr_t huge = std::uintptr_t(2) << 20;
    const auto begin = (reinterpret_cast<std::uintptr_t>(p) + huge - 1) & ~(huge - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(p) + n) & ~(huge - 1);
    if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

void write_value(Writer& w, const Value& v) {
    w.u8(std::uint8_t(v.type()));
    switch (v.type()) {
        case ValueType::heightmap: {
            const Heightmap& hm = *v.heightmap();
            w.i32(hm.width());
            w.i32(hm.height());
            w.f64(hm.cell());
            w.array(hm.heights());
            const auto names = hm.layer_names();
            w.u32(std::uint32_t(names.size()));
            for (const auto& n : names) {
                const ConstGridView l = hm.layer(n);
                w.str(n);
                w.array(l.data, l.size());
            }
            break;
        }
        case ValueType::image: {
            const Image& im = *v.image();
            w.i32(im.width);
            w.i32(im.height);
            w.u8(std::uint8_t(im.format));
            w.array(im.rgba8);
            w.array(im.rgba32f);
            break;
        }
        case ValueType::particles: {
            const ParticleSeries& ps = *v.particles();
            w.u64(ps.frames.size());
            for (const auto& f : ps.frames) {
                w.f64(f.time);
                w.i64(f.step);
                w.u32(std::uint32_t(f.attributes.size()));
                for (const auto& [name, a] : f.attributes) {
                    w.str(name);
                    w.i32(a.components);
                    w.array(a.data);
                }
            }
            break;
        }
        case ValueType::plates: {
            const PlateHistory& ph = *v.plates();
            w.f64(ph.width);
            w.f64(ph.height);
            w.u64(ph.snapshots.size());
            for (const auto& s : ph.snapshots) {
                w.i64(s.step);
                w.f64(s.time);
                w.u64(s.plates.size());
                for (const auto& p : s.plates) {
                    w.i32(p.id);
                    w.array(p.polygon);
                    w.f64(p.velocity.x);
                    w.f64(p.velocity.y);
                    w.f64(p.density);
                }
            }
            w.u64(ph.collisions.size());
            for (const auto& c : ph.collisions) {
                w.i64(c.step);
                w.i32(c.plate_a);
                w.i32(c.plate_b);
                w.f64(c.a.x);
                w.f64(c.a.y);
                w.f64(c.b.x);
                w.f64(c.b.y);
                w.i32(int(c.kind));
                w.f64(c.impulse);
            }
            break;
        }
        case ValueType::none:
        case ValueType::series:
            throw Error("internal error: a " + std::string(to_string(v.type())) + " cannot be kept in the cache");
    }
}

Value read_value(Reader& r) {
    const auto type = ValueType(r.u8());
    switch (type) {
        case ValueType::heightmap: {
            const int width = r.i32(), height = r.i32();
            const double cell = r.f64();
            if (width < 0 || height < 0) throw CorruptEntry("a heightmap of negative size");
            if (!std::isfinite(cell) || cell <= 0)
                throw CorruptEntry("a heightmap whose cell size is not a positive number");
            const std::size_t size = std::size_t(width) * std::size_t(height);
            // Heights first, then each layer: fresh vectors filled from the mapping (deferred: on every core, beside
            // the checksum), then adopted by the Heightmap, so no byte of it is written twice.
            auto hm = std::make_shared<Heightmap>();
            const auto heights = r.array_span<float>();
            if (heights.size() != size) throw CorruptEntry("a heightmap's size does not match its heights");
            const std::uint32_t layers = r.count32(16);  // each: a name's length and an array's count at least
            auto arrays =
                std::make_shared<std::vector<std::pair<std::string, std::vector<float>>>>(std::size_t(layers) + 1);
            r.copy_into((*arrays)[0].second, heights);
            for (std::uint32_t i = 1; i <= layers; ++i) {
                std::string name = r.str();
                for (std::uint32_t j = 1; j < i; ++j)
                    if ((*arrays)[j].first == name) throw CorruptEntry("a layer appears twice");
                const auto values = r.array_span<float>();
                if (values.size() != size) throw CorruptEntry("a layer's size does not match its heightmap");
                (*arrays)[i].first = std::move(name);
                r.copy_into((*arrays)[i].second, values);
            }
            auto assemble = [hm, arrays, width, height, cell] {
                *hm = Heightmap(width, height, cell, std::move((*arrays)[0].second));
                for (std::size_t i = 1; i < arrays->size(); ++i)
                    hm->set_layer((*arrays)[i].first, std::move((*arrays)[i].second));
                arrays->clear();
            };
            if (r.deferred()) r.deferred()->after.push_back(std::move(assemble));
            else assemble();
            return Value(std::move(hm));
        }
        case ValueType::image: {
            auto im = std::make_shared<Image>();
            im->width = r.i32();
            im->height = r.i32();
            const std::uint8_t format = r.u8();
            if (format > 1) throw CorruptEntry("an image of unknown format");
            if (im->width < 0 || im->height < 0) throw CorruptEntry("an image of negative size");
            im->format = Image::Format(format);
            const std::size_t samples = std::size_t(im->width) * std::size_t(im->height) * 4;
            const auto rgba8 = r.array_span<std::uint8_t>();
            const auto rgba32f = r.array_span<float>();
            // Exactly one of the two holds the pixels (values.hpp): a reader of the image trusts its size.
            if (rgba8.size() != (im->format == Image::Format::rgba8 ? samples : 0) ||
                rgba32f.size() != (im->format == Image::Format::rgba32f ? samples : 0))
                throw CorruptEntry("an image's pixels do not match its size and format");
            r.copy_into(im->rgba8, rgba8);
            r.copy_into(im->rgba32f, rgba32f);
            return Value(std::move(im));
        }
        case ValueType::particles: {
            auto ps = std::make_shared<ParticleSeries>();
            ps->frames.resize(r.count(20));
            for (auto& f : ps->frames) {
                f.time = r.f64();
                f.step = r.i64();
                const std::uint32_t n = r.count32(20);
                std::optional<std::size_t> particles;
                for (std::uint32_t i = 0; i < n; ++i) {
                    std::string name = r.str();
                    const std::int32_t components = r.i32();
                    if (components < 1)
                        throw CorruptEntry("a particle attribute of " + std::to_string(components) + " components");
                    const auto data = r.array_span<float>();
                    // Every attribute has `components` floats for each of the frame's particles.
                    if (data.size() % std::size_t(components) != 0 ||
                        (particles && data.size() / std::size_t(components) != *particles))
                        throw CorruptEntry("a particle attribute's size does not match the frame's particles");
                    particles = data.size() / std::size_t(components);
                    auto [it, inserted] = f.attributes.try_emplace(std::move(name));
                    if (!inserted) throw CorruptEntry("a particle attribute appears twice");
                    it->second.components = components;
                    r.copy_into(it->second.data, data);
                }
            }
            return Value(std::move(ps));
        }
        case ValueType::plates: {
            auto ph = std::make_shared<PlateHistory>();
            ph->width = r.f64();
            ph->height = r.f64();
            ph->snapshots.resize(r.count(24));
            for (auto& s : ph->snapshots) {
                s.step = r.i64();
                s.time = r.f64();
                s.plates.resize(r.count(36));
                for (auto& p : s.plates) {
                    p.id = r.i32();
                    r.array(p.polygon);
                    p.velocity.x = r.f64();
                    p.velocity.y = r.f64();
                    p.density = r.f64();
                }
            }
            ph->collisions.resize(r.count(60));
            for (auto& c : ph->collisions) {
                c.step = r.i64();
                c.plate_a = r.i32();
                c.plate_b = r.i32();
                c.a.x = r.f64();
                c.a.y = r.f64();
                c.b.x = r.f64();
                c.b.y = r.f64();
                const std::int32_t kind = r.i32();
                if (kind < 1 || kind > 3) throw CorruptEntry("a collision of unknown kind " + std::to_string(kind));
                c.kind = BoundaryKind(kind);
                c.impulse = r.f64();
            }
            return Value(std::move(ph));
        }
        default: throw CorruptEntry("a value of unknown type " + std::to_string(int(type)));
    }
}

std::size_t estimate(const Value& v) {
    std::size_t n = 256;
    switch (v.type()) {
        case ValueType::heightmap: {
            const auto& hm = *v.heightmap();
            n += (hm.layer_names().size() + 1) * (hm.size() * 4 + 128);
            break;
        }
        case ValueType::image: n += v.image()->rgba8.size() + v.image()->rgba32f.size() * 4 + 256; break;
        case ValueType::particles:
            for (const auto& f : v.particles()->frames)
                for (const auto& [name, a] : f.attributes) n += a.data.size() * 4 + name.size() + 128;
            break;
        case ValueType::plates:
            for (const auto& s : v.plates()->snapshots)
                for (const auto& p : s.plates) n += p.polygon.size() * 16 + 160;
            n += v.plates()->collisions.size() * 64;
            break;
        default: break;
    }
    return n;
}

bool storable(ValueType type) {
    return type == ValueType::heightmap || type == ValueType::image || type == ValueType::particles ||
        type == ValueType::plates;
}

Digest value_hash(const Value& value) {
    Writer w(estimate(value));
    write_value(w, value);
    return payload_hash(w.buffer());
}

}  // namespace orogen::cache
