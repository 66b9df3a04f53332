// export:gltf — files read back with tinygltf and checked by the Khronos validator.
#include <orogen/gltf/gltf_writer.hpp>

#include "export_test_support.hpp"
#include "orogen_test.hpp"

#include <orogen/error.hpp>

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

using namespace orogen;
namespace fs = std::filesystem;

namespace {

tinygltf::Model load(const fs::path& file) {
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = file.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, file.string())
                                               : loader.LoadASCIIFromFile(&model, &err, &warn, file.string());
    EXPECT_TRUE(ok) << err;
    EXPECT_EQ(warn, "");
    return model;
}

template <typename T>
std::vector<T> accessor_data(const tinygltf::Model& m, int accessor, int components) {
    const auto& a = m.accessors[std::size_t(accessor)];
    const auto& v = m.bufferViews[std::size_t(a.bufferView)];
    const auto& b = m.buffers[std::size_t(v.buffer)];
    std::vector<T> out(a.count * std::size_t(components));
    std::memcpy(out.data(), b.data.data() + v.byteOffset + a.byteOffset, out.size() * sizeof(T));
    return out;
}

/// Run tools/gltf-validate; "" if it cannot run here (reason in `skip`).
std::string validate(const fs::path& file, int& exit_code, std::string& skip) {
    const fs::path tool = fs::path(OROGEN_SOURCE_DIR) / "tools" / "gltf-validate";
    const fs::path module = fs::path(OROGEN_SOURCE_DIR) / "tools" / "node_modules" / "gltf-validator";
    if (std::system("node --version >/dev/null 2>&1") != 0) {
        skip = "node is not installed";
        return "";
    }
    if (!fs::exists(module)) {
        skip = "the gltf-validator npm package is missing (run: npm install --prefix tools)";
        return "";
    }
    const fs::path out = file.string() + ".report";
    const int status =
        std::system(("node " + test::q(tool) + " " + test::q(file) + " >" + test::q(out) + " 2>&1").c_str());
    exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return test::file_text(out);
}

struct Written {
    test::TempDir dir;
    std::vector<float> heights;
    int w = 65, h = 49;
    double cell = 10.0;
    fs::path file;
};

}  // namespace

TEST(Gltf, GlbReadsBackWithExactAccessorBoundsAndHeights) {
    test::TempDir dir;
    const int w = 65, h = 49;
    const double cell = 10.0, scale = 2.0;
    auto heights = test::hills(w, h);
    gltf::Options o;
    o.vertical_scale = scale;
    o.chunks = 2;
    const auto summary = gltf::write_gltf(ConstGridView(heights.data(), w, h, cell), o, dir / "t.glb");
    EXPECT_EQ(summary.meshes, 4u);
    EXPECT_EQ(summary.triangles, std::size_t(2 * 64 * 48));

    const auto m = load(dir / "t.glb");
    ASSERT_EQ(m.meshes.size(), 4u);
    ASSERT_EQ(m.scenes.size(), 1u);
    EXPECT_EQ(m.scenes[0].nodes.size(), 4u);
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    std::size_t triangles = 0;
    for (const auto& mesh : m.meshes) {
        ASSERT_EQ(mesh.primitives.size(), 1u);
        const auto& p = mesh.primitives[0];
        EXPECT_EQ(p.mode, TINYGLTF_MODE_TRIANGLES);
        const int pos = p.attributes.at("POSITION");
        const auto& acc = m.accessors[std::size_t(pos)];
        const auto xyz = accessor_data<float>(m, pos, 3);
        float amin[3] = {xyz[0], xyz[1], xyz[2]}, amax[3] = {xyz[0], xyz[1], xyz[2]};
        for (std::size_t i = 0; i < xyz.size(); i += 3) {
            for (int k = 0; k < 3; ++k) {
                amin[k] = std::min(amin[k], xyz[i + std::size_t(k)]);
                amax[k] = std::max(amax[k], xyz[i + std::size_t(k)]);
            }
            // Every vertex sits on the heightmap: Y = h(x, y) · scale at X = x·cell, Z = y·cell.
            const int x = int(std::lround(xyz[i] / cell)), y = int(std::lround(xyz[i + 2] / cell));
            ASSERT_FLOAT_EQ(xyz[i + 1], heights[std::size_t(y * w + x)] * float(scale));
        }
        ASSERT_EQ(acc.minValues.size(), 3u);
        ASSERT_EQ(acc.maxValues.size(), 3u);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(acc.minValues[std::size_t(k)], double(amin[k]));  // exactly
            EXPECT_EQ(acc.maxValues[std::size_t(k)], double(amax[k]));
            lo[k] = std::min(lo[k], amin[k]);
            hi[k] = std::max(hi[k], amax[k]);
        }
        // Normals are unit length and point up.
        const auto n = accessor_data<float>(m, p.attributes.at("NORMAL"), 3);
        for (std::size_t i = 0; i < n.size(); i += 3) {
            ASSERT_NEAR(std::sqrt(n[i] * n[i] + n[i + 1] * n[i + 1] + n[i + 2] * n[i + 2]), 1.0, 1e-5);
            ASSERT_GT(n[i + 1], 0.0f);
        }
        const auto& ia = m.accessors[std::size_t(p.indices)];
        EXPECT_EQ(ia.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);  // small chunks: 16-bit
        triangles += ia.count / 3;
        const auto& uv = m.accessors[std::size_t(p.attributes.at("TEXCOORD_0"))];
        EXPECT_TRUE(uv.normalized);
    }
    EXPECT_EQ(triangles, std::size_t(2 * 64 * 48));
    const auto [hmin, hmax] = std::minmax_element(heights.begin(), heights.end());
    EXPECT_EQ(lo[0], 0.0f);
    EXPECT_EQ(hi[0], float(64 * cell));
    EXPECT_EQ(hi[2], float(48 * cell));
    EXPECT_EQ(lo[1], *hmin * float(scale));
    EXPECT_EQ(hi[1], *hmax * float(scale));

    // The splat texture is embedded as a PNG and decodes at the terrain's tile count.
    ASSERT_EQ(m.images.size(), 1u);
    EXPECT_EQ(m.images[0].mimeType, "image/png");
    EXPECT_GE(m.images[0].bufferView, 0);
    EXPECT_EQ(m.images[0].width, 64);
    EXPECT_EQ(m.images[0].height, 48);
    ASSERT_EQ(m.materials.size(), 1u);
    EXPECT_EQ(m.materials[0].pbrMetallicRoughness.baseColorTexture.index, 0);
}

TEST(Gltf, GltfWithBinBesideItHoldsTheSameMesh) {
    test::TempDir dir;
    auto heights = test::hills(33, 33);
    gltf::Options o;
    o.decimate = 4;
    gltf::write_gltf(ConstGridView(heights.data(), 33, 33, 1.0), o, dir / "terrain.gltf");
    EXPECT_EQ(test::folder_entries(dir.path()), (std::vector<std::string>{"terrain.bin", "terrain.gltf"}));
    const auto m = load(dir / "terrain.gltf");
    ASSERT_EQ(m.buffers.size(), 1u);
    EXPECT_EQ(m.buffers[0].uri, "terrain.bin");
    EXPECT_EQ(m.buffers[0].data.size(), fs::file_size(dir / "terrain.bin"));
    ASSERT_EQ(m.meshes.size(), 1u);
    const auto& acc = m.accessors[std::size_t(m.meshes[0].primitives[0].attributes.at("POSITION"))];
    EXPECT_EQ(acc.count, 9u * 9u);  // decimate=4 keeps samples 0, 4, ..., 32
}

TEST(Gltf, BigChunkUses32BitIndices) {
    test::TempDir dir;
    auto heights = test::hills(300, 300);
    gltf::Options o;
    o.chunks = 1;
    o.texture_size = 64;
    gltf::write_gltf(ConstGridView(heights.data(), 300, 300, 1.0), o, dir / "big.glb");
    const auto m = load(dir / "big.glb");
    ASSERT_EQ(m.meshes.size(), 1u);
    const auto& ia = m.accessors[std::size_t(m.meshes[0].primitives[0].indices)];
    EXPECT_EQ(ia.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
    EXPECT_EQ(ia.count, std::size_t(299 * 299 * 6));
    const auto idx = accessor_data<std::uint32_t>(m, m.meshes[0].primitives[0].indices, 1);
    EXPECT_EQ(*std::max_element(idx.begin(), idx.end()), 300u * 300u - 1u);
}

TEST(Gltf, KhronosValidatorReportsNoErrorsAndNoWarnings) {
    test::TempDir dir;
    auto heights = test::hills(65, 65);
    const ConstGridView g(heights.data(), 65, 65, 20.0);
    gltf::Options chunked;
    chunked.chunks = 3;
    chunked.decimate = 2;
    gltf::write_gltf(g, chunked, dir / "a.glb");
    gltf::write_gltf(g, gltf::Options{}, dir / "b.gltf");
    auto big = test::hills(300, 260);
    gltf::Options one;
    one.chunks = 1;
    gltf::write_gltf(ConstGridView(big.data(), 300, 260, 5.0), one, dir / "c.glb");
    for (const char* name : {"a.glb", "b.gltf", "c.glb"}) {
        int code = -1;
        std::string skip;
        const std::string report = validate(dir / name, code, skip);
        if (!skip.empty()) GTEST_SKIP() << "SKIPPED glTF validation: " << skip;
        EXPECT_EQ(code, 0) << name << ":\n" << report;
        EXPECT_NE(report.find("errors 0 warnings 0"), std::string::npos) << name << ":\n" << report;
    }
}

TEST(Gltf, UnknownExtensionIsBadInput) {
    test::TempDir dir;
    auto heights = test::hills(9, 9);
    try {
        gltf::write_gltf(ConstGridView(heights.data(), 9, 9, 1.0), {}, dir / "t.obj");
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "export:gltf writes .glb or .gltf files; 't.obj' has another extension");
    }
    EXPECT_TRUE(test::folder_entries(dir.path()).empty());
}

TEST(Gltf, UnwritableFolderFailsWithoutLeavingAFile) {
    auto heights = test::hills(9, 9);
    const fs::path target = test::unwritable_folder() / "orogen-test.glb";
    EXPECT_THROW(gltf::write_gltf(ConstGridView(heights.data(), 9, 9, 1.0), {}, target), Error);
    EXPECT_FALSE(fs::exists(target));
}

TEST(Gltf, FullDiskKeepsTheGoodFileAndLeavesNoTemporary) {
    test::TempDir dir;
    test::TinyDisk disk(dir / "tiny");
    OROGEN_SKIP_WITHOUT_TINY_DISK(disk);
    auto heights = test::hills(65, 65);
    const ConstGridView g(heights.data(), 65, 65, 1.0);
    for (const char* name : {"t.glb", "t.gltf"}) {
        for (const auto& e : fs::directory_iterator(disk.path())) fs::remove(e.path());
        const fs::path target = disk.path() / name;
        std::ofstream(target) << "good";
        if (std::string(name) == "t.gltf") std::ofstream(disk.path() / "t.bin") << "good bin";
        const auto before = test::folder_entries(disk.path());
        EXPECT_THROW(gltf::write_gltf(g, {}, target), Error) << name;  // ~250 KB does not fit in 64 KiB
        EXPECT_EQ(test::file_text(target), "good");
        EXPECT_EQ(test::folder_entries(disk.path()), before) << "a temporary file was left behind";
    }
    EXPECT_EQ(test::file_text(disk.path() / "t.bin"), "good bin");
}
