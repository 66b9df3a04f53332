// The only translation unit that includes tinygltf (Debian ships its
// implementation as libtinygltf.so, so no TINYGLTF_IMPLEMENTATION here).
//
// tinygltf builds and serialises the whole glTF document (accessors, views,
// meshes, material, texture, image). The binary payload is streamed by us:
// tinygltf's own GLB writer copies the buffer once more (buffer.data →
// binBuffer), which would double the peak memory of a 4097² export (~700 MB
// of vertex data). So the document is serialised with an empty buffer and
// the buffer's byteLength (and, for .gltf, its uri) is set in the JSON text
// afterwards; then each chunk's vertices are generated and written one
// attribute at a time. Peak memory: the heightmap, the texture, one chunk.
#include <orogen/gltf/gltf_writer.hpp>

#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <functional>
#include <future>
#include <memory>
#include <type_traits>
#include <optional>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen::gltf {

namespace {

/// The embedded texture's libdeflate level: the fastest (a texture is baked and encoded on every export; the
/// file is mostly mesh).
constexpr int kTextureLevel = 1;

struct ChunkViews {
    std::size_t positions = 0, normals = 0, texcoords = 0, indices = 0;  // byte offsets in the buffer
    std::size_t vertex_count = 0, index_count = 0;
    bool index16 = true;
};

std::size_t align4(std::size_t n) { return (n + 3) & ~std::size_t(3); }

void put_u32(std::string& s, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s.push_back(char((v >> (8 * i)) & 0xff));
}

template <typename T>
void write_span(std::ostream& out, std::span<const T> data) {
    out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size_bytes()));
}

void write_zeros(std::ostream& out, std::size_t n) {
    static const char zeros[4] = {0, 0, 0, 0};
    out.write(zeros, std::streamsize(n));
}

int add_view(tinygltf::Model& model, std::size_t off, std::size_t len, int target_kind) {
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = off;
    bv.byteLength = len;
    bv.target = target_kind;
    model.bufferViews.push_back(bv);
    return int(model.bufferViews.size() - 1);
}

int add_accessor(tinygltf::Model& model, int view, int component, int type, std::size_t count, bool normalized) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = 0;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.normalized = normalized;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
}

/// Material 0: the PNG at [png_offset, + png_size) of the buffer as base colour, rough dielectric.
void add_splat_material(tinygltf::Model& model, std::size_t png_offset, std::size_t png_size) {
    tinygltf::Image image;
    image.name = "splat";
    image.mimeType = "image/png";
    image.bufferView = add_view(model, png_offset, png_size, 0);
    model.images.push_back(image);
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    model.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.sampler = 0;
    texture.source = 0;
    model.textures.push_back(texture);
    tinygltf::Material material;
    material.name = "terrain";
    material.pbrMetallicRoughness.baseColorTexture.index = 0;
    material.pbrMetallicRoughness.metallicFactor = 0.0;
    material.pbrMetallicRoughness.roughnessFactor = 1.0;
    model.materials.push_back(material);
}

/// Write `model` to `target` (.glb, or .gltf with its buffer beside it as <stem>.bin), atomically. The
/// model's one buffer is left empty: its buffer_length bytes are streamed by `payload_writer` (see the
/// top of this file).
/// Starts the disk writing what a large file holds so far, without waiting for it (Linux's
/// sync_file_range): the fsync of AtomicFile::commit then waits only for the last few chunks rather than
/// the whole file, and the disk writes while the next chunks are computed. Page-cache writeback is per
/// file, so a read-only descriptor of the temporary file serves. Errors are left to commit's fsync, which
/// reports them; where the call is unsupported this only loses the overlap.
class Writeback {
public:
    explicit Writeback(AtomicFile& file) : file_(file), fd_(::open(file.temporary().c_str(), O_RDONLY | O_CLOEXEC)) {}
    ~Writeback() {
        if (fd_ >= 0) ::close(fd_);
    }
    Writeback(const Writeback&) = delete;
    Writeback& operator=(const Writeback&) = delete;
    /// After `written` bytes of the file: start writing what was not yet started.
    void start(std::uint64_t written) {
        if (fd_ < 0 || written <= started_) return;
        file_.stream().flush();
        ::sync_file_range(fd_, off64_t(started_), off64_t(written - started_), SYNC_FILE_RANGE_WRITE);
        started_ = written;
    }

private:
    AtomicFile& file_;
    int fd_;
    std::uint64_t started_ = 0;
};

/// The binary payload's writer: its stream, and `written(n)` after each large piece, n the payload's bytes
/// so far, which starts that much on its way to the disk (Writeback).
struct Payload {
    std::ostream& out;
    std::function<void(std::uint64_t)> written;
};

void write_document(const tinygltf::Model& model, std::size_t buffer_length, const fs::path& target,
                    const std::function<void(Payload&)>& payload_writer) {
    const bool binary = target.extension() == ".glb";
    // Serialise with tinygltf (as a GLB without payload) and take its JSON chunk.
    std::string json;
    {
        tinygltf::TinyGLTF writer;
        std::ostringstream s(std::ios::binary);
        tinygltf::Model copy = model;  // WriteGltfSceneToStream takes a non-const model
        if (!writer.WriteGltfSceneToStream(&copy, s, false, true))
            throw Error("tinygltf could not serialise the glTF document");
        const std::string glb = std::move(s).str();
        std::uint32_t json_length = 0;
        if (glb.size() < 20) throw Error("tinygltf wrote a truncated GLB header");
        std::memcpy(&json_length, glb.data() + 12, 4);
        json = glb.substr(20, json_length);
        while (!json.empty() && json.back() == ' ') json.pop_back();
    }
    const std::string placeholder = "\"buffers\":[{\"byteLength\":0}]";
    const auto at = json.find(placeholder);
    if (at == std::string::npos) throw Error("internal error: tinygltf's JSON has no empty buffer to fill in");
    const fs::path bin_target = fs::path(target).replace_extension(".bin");
    std::string buffer_json = "\"buffers\":[{\"byteLength\":" + std::to_string(buffer_length);
    if (!binary) buffer_json += ",\"uri\":\"" + bin_target.filename().string() + "\"";
    buffer_json += "}]";
    json.replace(at, placeholder.size(), buffer_json);

    AtomicFile main_file(target);
    std::optional<AtomicFile> bin_file;
    std::ostream* payload = &main_file.stream();
    if (binary) {
        // GLB: 12-byte header, JSON chunk (padded with spaces), BIN chunk (padded with zeros).
        const std::size_t json_padded = align4(json.size());
        json.append(json_padded - json.size(), ' ');
        const std::size_t total = 12 + 8 + json_padded + 8 + buffer_length;
        if (total > 0xffffffffu)
            throw BadInput("the GLB would be " + std::to_string(total >> 20) +
                           " MiB, over the format's 4 GiB limit; use decimate=2 or more");
        std::string head;
        put_u32(head, 0x46546C67);  // "glTF"
        put_u32(head, 2);
        put_u32(head, std::uint32_t(total));
        put_u32(head, std::uint32_t(json_padded));
        put_u32(head, 0x4E4F534A);  // "JSON"
        head += json;
        put_u32(head, std::uint32_t(buffer_length));
        put_u32(head, 0x004E4942);  // "BIN\0"
        main_file.stream().write(head.data(), std::streamsize(head.size()));
    } else {
        main_file.stream().write(json.data(), std::streamsize(json.size()));
        bin_file.emplace(bin_target);
        payload = &bin_file->stream();
    }
    AtomicFile& payload_file = bin_file ? *bin_file : main_file;
    const std::uint64_t payload_start = binary ? std::uint64_t(payload->tellp()) : 0;
    Writeback writeback(payload_file);
    Payload p{*payload, [&](std::uint64_t n) { writeback.start(payload_start + n); }};
    payload_writer(p);
    if (bin_file) {
        AtomicFile* files[] = {&*bin_file, &main_file};  // the .bin in place before the .gltf names it
        commit_all(files);
    } else {
        main_file.commit();
    }
}

}  // namespace

Summary write_gltf(ConstGridView heights, const Options& options, const fs::path& target) {
    const std::string ext = target.extension().string();
    const bool binary = ext == ".glb";
    if (!binary && ext != ".gltf")
        throw BadInput("export:gltf writes .glb or .gltf files; '" + target.filename().string() +
                       "' has another extension");
    if (options.texture_size < 1) throw BadInput("texture must be at least 1 pixel");

    const mesh::TerrainMesh mesh = mesh::plan_mesh(heights, options.decimate, options.chunks, options.vertical_scale);

    // Texture: no larger than the terrain's tile count (more pixels than tiles add nothing).
    const int tw = std::max(1, std::min(options.texture_size, heights.width - 1));
    const int th = std::max(1, std::min(options.texture_size, heights.height - 1));
    const std::vector<std::uint8_t> png =
        encode_rgba_png(mesh::bake_splat_texture(heights, tw, th), tw, th, kTextureLevel);

    // Buffer layout: per chunk positions, normals, texcoords, indices; then the PNG.
    std::vector<ChunkViews> views;
    std::size_t offset = 0;
    for (const auto& c : mesh.chunks) {
        ChunkViews v;
        v.vertex_count = c.vertex_count();
        v.index_count = c.triangle_count() * 3;
        v.index16 = c.fits_16bit();
        v.positions = offset;
        offset += v.vertex_count * 12;
        v.normals = offset;
        offset += v.vertex_count * 12;
        v.texcoords = offset;
        offset += v.vertex_count * 4;  // 2 × uint16 normalised
        v.indices = offset;
        offset = align4(offset + v.index_count * (v.index16 ? 2 : 4));
        views.push_back(v);
    }
    const std::size_t png_offset = offset;
    const std::size_t buffer_length = align4(png_offset + png.size());

    // ------------------------------------------------------------ document
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "orogen export:gltf";
    model.buffers.emplace_back();  // empty here; its length is set in the JSON below

    add_splat_material(model, png_offset, png.size());

    tinygltf::Scene scene;
    scene.name = "terrain";
    const int per_row = int(std::count_if(mesh.chunks.begin(), mesh.chunks.end(),
                                          [&](const auto& c) { return c.row_begin == mesh.chunks[0].row_begin; }));
    for (std::size_t i = 0; i < mesh.chunks.size(); ++i) {
        const auto& v = views[i];
        const auto bounds = mesh::chunk_bounds(mesh, mesh.chunks[i]);
        const int pos =
            add_accessor(model, add_view(model, v.positions, v.vertex_count * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                         TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, v.vertex_count, false);
        model.accessors[std::size_t(pos)].minValues.assign(bounds.min.begin(), bounds.min.end());
        model.accessors[std::size_t(pos)].maxValues.assign(bounds.max.begin(), bounds.max.end());
        const int nrm =
            add_accessor(model, add_view(model, v.normals, v.vertex_count * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                         TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, v.vertex_count, false);
        const int uv =
            add_accessor(model, add_view(model, v.texcoords, v.vertex_count * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC2, v.vertex_count, true);
        const int idx = add_accessor(
            model,
            add_view(model, v.indices, v.index_count * (v.index16 ? 2 : 4), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
            v.index16 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
            TINYGLTF_TYPE_SCALAR, v.index_count, false);
        tinygltf::Primitive prim;
        prim.attributes["POSITION"] = pos;
        prim.attributes["NORMAL"] = nrm;
        prim.attributes["TEXCOORD_0"] = uv;
        prim.indices = idx;
        prim.material = 0;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Mesh m;
        m.name = mesh.chunks.size() == 1
            ? std::string("terrain")
            : "terrain_" + std::to_string(int(i) % per_row) + "_" + std::to_string(int(i) / per_row);
        m.primitives.push_back(prim);
        model.meshes.push_back(m);
        tinygltf::Node node;
        node.name = m.name;
        node.mesh = int(i);
        model.nodes.push_back(node);
        scene.nodes.push_back(int(i));
    }
    model.scenes.push_back(scene);
    model.defaultScene = 0;

    Summary summary;
    summary.meshes = mesh.chunks.size();
    summary.texture_width = tw;
    summary.texture_height = th;
    summary.bytes = buffer_length;
    // Generate chunk i + 1 while chunk i is written: writing is a copy into the
    // page cache on one core, generation runs on the others. Two buffers, made
    // once at the largest chunk's size and never zeroed (every byte is written
    // but the indices' padding, zeroed by hand): a fresh zeroed buffer a chunk
    // cost a memset and its page faults, 40 % of a 4097² export.
    auto chunk_bytes = [&](const ChunkViews& v) {
        return v.vertex_count * 28 + align4(v.index_count * (v.index16 ? 2 : 4));
    };
    std::size_t largest = 0;
    for (const auto& v : views) largest = std::max(largest, chunk_bytes(v));
    std::array<std::unique_ptr<std::uint8_t[]>, 2> buffers{std::unique_ptr<std::uint8_t[]>(new std::uint8_t[largest]),
                                                           std::unique_ptr<std::uint8_t[]>(new std::uint8_t[largest])};
    auto build = [&](std::size_t i, std::uint8_t* bytes) {
        const auto& c = mesh.chunks[i];
        const auto& v = views[i];
        const std::size_t index_bytes = v.index_count * (v.index16 ? 2 : 4);
        auto as = [&](std::size_t offset, auto* type, std::size_t n) {
            using T = std::remove_pointer_t<decltype(type)>;
            return std::span<T>(reinterpret_cast<T*>(bytes + offset), n);
        };
        mesh::chunk_positions(mesh, c, as(0, (float*)nullptr, v.vertex_count * 3));
        mesh::chunk_normals(mesh, c, as(v.vertex_count * 12, (float*)nullptr, v.vertex_count * 3));
        mesh::chunk_texcoords(mesh, c, as(v.vertex_count * 24, (std::uint16_t*)nullptr, v.vertex_count * 2));
        if (v.index16) mesh::chunk_indices(c, as(v.vertex_count * 28, (std::uint16_t*)nullptr, v.index_count));
        else mesh::chunk_indices(c, as(v.vertex_count * 28, (std::uint32_t*)nullptr, v.index_count));
        const std::size_t used = v.vertex_count * 28 + index_bytes, size = chunk_bytes(v);
        std::fill(bytes + used, bytes + size, std::uint8_t(0));
        return size;
    };
    write_document(model, buffer_length, target, [&](Payload& out) {
        std::ostream& payload = out.out;
        std::uint64_t written = 0;
        // Chunk i is built into buffers[i % 2]; chunk i + 1's build starts once chunk i - 1, the last user of
        // its buffer, has been written.
        std::future<std::size_t> next = std::async(std::launch::async, build, 0, buffers[0].get());
        for (std::size_t i = 0; i < mesh.chunks.size(); ++i) {
            const std::size_t size = next.get();
            if (i + 1 < mesh.chunks.size())
                next = std::async(std::launch::async, build, i + 1, buffers[(i + 1) % 2].get());
            summary.vertices += views[i].vertex_count;
            summary.triangles += mesh.chunks[i].triangle_count();
            payload.write(reinterpret_cast<const char*>(buffers[i % 2].get()), std::streamsize(size));
            written += size;
            out.written(written);  // the disk writes this chunk while the next ones are built
        }
        payload.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
        write_zeros(payload, buffer_length - png_offset - png.size());
    });
    return summary;
}

std::size_t write_mesh(const MeshData& mesh, std::span<const std::uint8_t> png, std::array<double, 3> translation,
                       const std::string& name, const fs::path& target) {
    const std::string ext = target.extension().string();
    if (ext != ".glb" && ext != ".gltf")
        throw BadInput("glTF files end in .glb or .gltf; '" + target.filename().string() + "' has another extension");
    const std::size_t vertices = mesh.positions.size() / 3;
    if (mesh.normals.size() != 3 * vertices || mesh.texcoords.size() != 2 * vertices || mesh.indices.size() % 3)
        throw Error("internal error: a mesh whose attributes disagree on its vertex count");
    const bool index16 = vertices <= mesh::max_16bit_vertices;
    const std::size_t pos = 0, nrm = pos + vertices * 12, uv = nrm + vertices * 12, idx = uv + vertices * 4;
    const std::size_t index_bytes = mesh.indices.size() * (index16 ? 2 : 4);
    const std::size_t png_offset = align4(idx + index_bytes), buffer_length = align4(png_offset + png.size());

    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "orogen export:tiles";
    model.buffers.emplace_back();  // empty here; its length is set by write_document
    add_splat_material(model, png_offset, png.size());
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = add_accessor(model, add_view(model, pos, vertices * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                                               TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertices, false);
    model.accessors.back().minValues.assign(mesh.min.begin(), mesh.min.end());
    model.accessors.back().maxValues.assign(mesh.max.begin(), mesh.max.end());
    prim.attributes["NORMAL"] = add_accessor(model, add_view(model, nrm, vertices * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertices, false);
    prim.attributes["TEXCOORD_0"] =
        add_accessor(model, add_view(model, uv, vertices * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC2, vertices, true);
    prim.indices = add_accessor(model, add_view(model, idx, index_bytes, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                                index16 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                TINYGLTF_TYPE_SCALAR, mesh.indices.size(), false);
    prim.material = 0;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh m;
    m.name = name;
    m.primitives.push_back(prim);
    model.meshes.push_back(m);
    tinygltf::Node node;
    node.name = name;
    node.mesh = 0;
    node.translation.assign(translation.begin(), translation.end());
    model.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.name = name;
    scene.nodes.push_back(0);
    model.scenes.push_back(scene);
    model.defaultScene = 0;

    write_document(model, buffer_length, target, [&](Payload& payload) {
        std::ostream& out = payload.out;
        write_span(out, mesh.positions);
        write_span(out, mesh.normals);
        write_span(out, mesh.texcoords);
        if (index16) {
            std::vector<std::uint16_t> narrow(mesh.indices.begin(), mesh.indices.end());
            write_span<std::uint16_t>(out, narrow);
        } else {
            write_span(out, mesh.indices);
        }
        write_zeros(out, png_offset - idx - index_bytes);
        out.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
        write_zeros(out, buffer_length - png_offset - png.size());
    });
    return buffer_length;
}

}  // namespace orogen::gltf
