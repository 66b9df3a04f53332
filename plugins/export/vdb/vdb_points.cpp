// Particles as OpenVDB points (the other translation unit that includes OpenVDB;
// the points headers are heavy, so they compile apart from the level sets).
#include "vdb_writer.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <cstdio>
#include <memory>

namespace fs = std::filesystem;

namespace orogen::vdb {

namespace {

openvdb::points::PointDataGrid::Ptr frame_grid(const ParticleFrame& frame, std::size_t index, double voxel_size) {
    using namespace openvdb;
    const auto pos = frame.attributes.find("position");
    if (pos == frame.attributes.end() || pos->second.components != 3)
        throw Error("particle frame " + std::to_string(index) + " has no 3-component 'position' attribute");
    const std::size_t n = frame.count();
    std::vector<Vec3f> positions(n);
    for (std::size_t i = 0; i < n; ++i)
        positions[i] = Vec3f(pos->second.data[3 * i], pos->second.data[3 * i + 1], pos->second.data[3 * i + 2]);
    const points::PointAttributeVector<Vec3f> wrapper(positions);
    float voxel = float(voxel_size);
    if (!(voxel > 0)) voxel = n > 1 ? points::computeVoxelSize(wrapper, 8) : 1.0f;
    auto transform = math::Transform::createLinearTransform(voxel);
    auto index_grid = tools::createPointIndexGrid<tools::PointIndexGrid>(wrapper, *transform);
    auto grid = points::createPointDataGrid<points::NullCodec, points::PointDataGrid>(*index_grid, wrapper, *transform);
    for (const auto& [name, attr] : frame.attributes) {
        if (name == "position") continue;
        if (attr.data.size() != n * std::size_t(attr.components))
            throw Error("particle frame " + std::to_string(index) + ": attribute '" + name + "' holds " +
                        std::to_string(attr.data.size()) + " values for " + std::to_string(n) + " particles of " +
                        std::to_string(attr.components) + " components");
        if (attr.components == 3) {
            std::vector<Vec3f> values(n);
            for (std::size_t i = 0; i < n; ++i)
                values[i] = Vec3f(attr.data[3 * i], attr.data[3 * i + 1], attr.data[3 * i + 2]);
            points::appendAttribute<Vec3f>(grid->tree(), name);
            points::populateAttribute(grid->tree(), index_grid->tree(), name,
                                      points::PointAttributeVector<Vec3f>(values));
        } else {
            // Scalars, and other widths as a float array of `components` per point.
            points::appendAttribute<float>(grid->tree(), name, 0.0f, Index(attr.components));
            points::populateAttribute(grid->tree(), index_grid->tree(), name,
                                      points::PointAttributeVector<float>(attr.data, Index(attr.components)),
                                      Index(attr.components));
        }
    }
    grid->setName("particles");
    grid->insertMeta("time", DoubleMetadata(frame.time));
    grid->insertMeta("step", Int64Metadata(frame.step));
    grid->insertMeta("units", StringMetadata("m"));
    return grid;
}

void write_grid(AtomicFile& file, openvdb::GridBase::Ptr grid) {
    try {
        openvdb::io::Stream(file.stream()).write(openvdb::GridCPtrVec{grid});
    } catch (const openvdb::Exception& e) {
        throw Error("cannot write " + file.target().string() + ": OpenVDB: " + e.what());
    }
    stamp_content_uuid(file);
}

}  // namespace

std::size_t write_particles(const ParticleSeries& series, const fs::path& target, double voxel_size) {
    if (target.extension() != ".vdb")
        throw BadInput("export:vdb-particles writes .vdb files; '" + target.filename().string() +
                       "' has another extension");
    if (series.frames.empty()) throw BadInput("the particle series has no frames to write");
    initialize_once();
    std::vector<std::unique_ptr<AtomicFile>> files;
    for (std::size_t i = 0; i < series.frames.size(); ++i) {
        fs::path path = target;
        if (series.frames.size() > 1) {
            char digits[32];
            std::snprintf(digits, sizeof digits, "_%06zu.vdb", i);
            path = target.parent_path() / (target.stem().string() + digits);
        }
        files.push_back(std::make_unique<AtomicFile>(path));
        write_grid(*files.back(), frame_grid(series.frames[i], i, voxel_size));
    }
    std::vector<AtomicFile*> list;
    for (auto& f : files) list.push_back(f.get());
    commit_all(list);
    return files.size();
}

}  // namespace orogen::vdb
