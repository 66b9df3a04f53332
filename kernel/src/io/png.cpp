// PNG codec: reading on libpng (16-bit grayscale needs it; stb writes only 8
// bits), writing by hand over libdeflate: at level 6 about twice as fast as
// libpng + zlib for a file 3 % larger (bench_export_png). libpng reports errors by longjmp: each reading
// function below keeps only plain data alive across setjmp and turns the
// recorded message into an exception after.
#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <libdeflate.h>
#include <png.h>
#include <zlib.h>

#include <array>
#include <memory>

#include <csetjmp>
#include <cstring>
#include <span>
#include <ostream>

namespace orogen {

namespace {

struct ErrorSlot {
    char message[256] = {0};
};

void on_error(png_structp png, png_const_charp msg) {
    auto* slot = static_cast<ErrorSlot*>(png_get_error_ptr(png));
    std::snprintf(slot->message, sizeof slot->message, "%s", msg);
    png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

struct MemoryReader {
    const std::uint8_t* data;
    std::size_t size;
    std::size_t offset;
};

void read_from_memory(png_structp png, png_bytep out, png_size_t n) {
    auto* r = static_cast<MemoryReader*>(png_get_io_ptr(png));
    if (r->offset + n > r->size) png_error(png, "the file is truncated (it ends in the middle of the image data)");
    std::memcpy(out, r->data + r->offset, n);
    r->offset += n;
}

/// What the header says.
struct Header {
    png_uint_32 w = 0, h = 0;
    int bit_depth = 0, colour_type = 0;
    bool wrong_format = false;  ///< not grayscale
};

/// Plain-data decoder: the header into `hd`, then (unless `out` is empty, the format is wrong or the image
/// does not fit `out`) the samples. Returns 0 on success, else fills err. The header's fields are always
/// set if it was read.
int decode(std::span<const std::uint8_t> bytes, ErrorSlot& err, Header& hd, std::span<std::uint16_t> out) {
    MemoryReader reader{bytes.data(), bytes.size(), 0};
    png_uint_32& w = hd.w;
    png_uint_32& h = hd.h;
    int& bit_depth = hd.bit_depth;
    int& colour_type = hd.colour_type;
    bool& wrong_format = hd.wrong_format;
    const bool header_only = out.empty();
    std::uint16_t* const samples = out.data();
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info) {
        std::snprintf(err.message, sizeof err.message, "out of memory");
        return 1;
    }
    png_bytep volatile row = nullptr;  // volatile: it must survive the longjmp
    if (setjmp(png_jmpbuf(png))) {
        std::free(static_cast<void*>(row));
        png_destroy_read_struct(&png, &info, nullptr);
        return 1;
    }
    png_set_read_fn(png, &reader, read_from_memory);
    png_read_info(png, info);
    w = png_get_image_width(png, info);
    h = png_get_image_height(png, info);
    bit_depth = png_get_bit_depth(png, info);
    colour_type = png_get_color_type(png, info);
    wrong_format = colour_type != PNG_COLOR_TYPE_GRAY && colour_type != PNG_COLOR_TYPE_GRAY_ALPHA;
    if (header_only || wrong_format || std::size_t(w) * h > out.size()) {
        png_destroy_read_struct(&png, &info, nullptr);
        return 0;
    }
    if (bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (colour_type & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);
    if (bit_depth == 16) png_set_swap(png);  // PNG stores big-endian; we want host order
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    const std::size_t rowbytes = png_get_rowbytes(png, info);
    row = static_cast<png_bytep>(std::malloc(rowbytes));
    for (int pass = 0; pass < passes; ++pass) {
        for (png_uint_32 y = 0; y < h; ++y) {
            std::uint16_t* dst = samples + std::size_t(y) * w;
            if (pass > 0) {  // interlaced: feed back the row we have so far
                if (bit_depth == 16) std::memcpy(row, dst, std::size_t(w) * 2);
                else
                    for (png_uint_32 x = 0; x < w; ++x) row[x] = png_byte(dst[x]);
            }
            png_read_row(png, row, nullptr);
            if (bit_depth == 16) std::memcpy(dst, row, std::size_t(w) * 2);
            else
                for (png_uint_32 x = 0; x < w; ++x) dst[x] = row[x];
        }
    }
    png_read_end(png, nullptr);
    std::free(static_cast<void*>(row));
    png_destroy_read_struct(&png, &info, nullptr);
    return 0;
}

std::uint32_t be32(const std::uint8_t* p) {
    return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) | p[3];
}

/// Walk the chunks (after the signature) without decoding: "" and the image data's size if the file runs
/// whole to its end marker, else why it does not. Costs nothing next to inflating, and lets a cut file fail
/// before a buffer is allocated for its pixels.
std::string chunk_problem(const std::vector<std::uint8_t>& bytes, std::uint64_t& idat_bytes) {
    std::size_t at = 8;
    idat_bytes = 0;
    while (true) {
        if (bytes.size() - at < 12)
            return "truncated PNG (the file ends at byte " + std::to_string(bytes.size()) +
                ", before its end marker IEND); it was cut short: copy it again";
        const std::uint64_t length = be32(&bytes[at]);
        if (length > 0x7fffffffu)
            return "damaged PNG (a chunk at byte " + std::to_string(at) + " declares an impossible length)";
        if (bytes.size() - at - 12 < length)
            return "truncated PNG (the file ends at byte " + std::to_string(bytes.size()) +
                ", inside a chunk that declares " + std::to_string(length) +
                " bytes; the end marker IEND is missing); it was cut short: copy it again";
        if (std::memcmp(&bytes[at + 4], "IDAT", 4) == 0) idat_bytes += length;
        if (std::memcmp(&bytes[at + 4], "IEND", 4) == 0) return "";
        at += 12 + std::size_t(length);
    }
}

GrayImage read_png(const std::vector<std::uint8_t>& bytes, const std::filesystem::path& path, bool header_only) {
    static const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (bytes.size() < 8 || std::memcmp(bytes.data(), signature, 8) != 0)
        throw BadInput("cannot read " + path.string() + ": not a PNG file (it does not start with the PNG signature)");
    ErrorSlot err;
    Header hd;
    const png_uint_32 &w = hd.w, &h = hd.h;
    const int &bit_depth = hd.bit_depth, &colour_type = hd.colour_type;
    // Header first, to size the buffer and check the format before decoding.
    if (decode(bytes, err, hd, {}) != 0)
        throw BadInput("cannot read " + path.string() + ": damaged PNG (" + err.message + ")");
    if (hd.wrong_format) {
        const char* what = colour_type == PNG_COLOR_TYPE_PALETTE ? "a palette (indexed colour) image"
            : (colour_type & PNG_COLOR_MASK_ALPHA)               ? "an RGBA colour image"
                                                                 : "an RGB colour image";
        throw BadInput("cannot read " + path.string() + ": it is " + what +
                       ", but a heightmap must be a grayscale PNG (8 or 16 bits); convert it, e.g. "
                       "`convert in.png -colorspace gray -depth 16 out.png`");
    }
    // Bounded decoding: the declared size against the memory budget, then the data against the size,
    // all before a byte is allocated for pixels.
    if (const std::string problem = heightmap_memory_problem(double(w), double(h)); !problem.empty())
        throw BadInput("cannot read " + path.string() + ": its header declares " + std::to_string(w) + "x" +
                       std::to_string(h) + " pixels, which " + problem);
    std::uint64_t idat_bytes = 0;
    if (const std::string problem = chunk_problem(bytes, idat_bytes); !problem.empty())
        throw BadInput("cannot read " + path.string() + ": " + problem);
    // Deflate packs at most 1032 bytes into one, so fewer image bytes than pixels/1032 cannot be whole.
    const double pixel_bytes = double(w) * double(h) * double(bit_depth) / 8.0;
    if (double(idat_bytes) * 1032.0 + 1024.0 < pixel_bytes)
        throw BadInput("cannot read " + path.string() + ": damaged PNG (its " + std::to_string(w) + "x" +
                       std::to_string(h) + " pixels need at least " + human_bytes(pixel_bytes / 1032.0) +
                       " of compressed image data, but it holds " + human_bytes(double(idat_bytes)) + ")");
    GrayImage image;
    image.width = int(w);
    image.height = int(h);
    image.bits = bit_depth == 16 ? 16 : 8;
    if (header_only) return image;
    image.samples.resize(std::size_t(w) * h);
    if (decode(bytes, err, hd, image.samples) != 0)
        throw BadInput("cannot read " + path.string() + ": damaged PNG (" + err.message + ")");
    if (bit_depth < 8) {  // expanded to 8 bits without rescaling: scale 0..2^d-1 to 0..255
        const int max = (1 << bit_depth) - 1;
        for (auto& s : image.samples) s = std::uint16_t((s * 255 + max / 2) / max);
    }
    return image;
}

// ---- writing

void put_u32(std::uint8_t* p, std::uint32_t v) {
    p[0] = std::uint8_t(v >> 24), p[1] = std::uint8_t(v >> 16), p[2] = std::uint8_t(v >> 8), p[3] = std::uint8_t(v);
}

void write_chunk(std::ostream& out, const char type[4], const std::uint8_t* data, std::size_t size) {
    std::uint8_t head[8];
    put_u32(head, std::uint32_t(size));
    std::memcpy(head + 4, type, 4);
    std::uint32_t crc = libdeflate_crc32(0, head + 4, 4);
    if (size > 0) crc = libdeflate_crc32(crc, data, size);  // (a null buffer would restart the CRC)
    std::uint8_t tail[4];
    put_u32(tail, crc);
    out.write(reinterpret_cast<const char*>(head), 8);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    out.write(reinterpret_cast<const char*>(tail), 4);
}

// Each scanline with the filter (none, sub, up, average, Paeth) whose output has the smallest sum of absolute
// values as signed bytes: libpng's own heuristic for colour and grey images. `raw` holds the rows as PNG
// stores them (big-endian samples); `bpp` is bytes per pixel (the filters' left neighbour).
std::vector<std::uint8_t> filter_rows(const std::uint8_t* raw, int height, std::size_t row_bytes, int bpp) {
    std::vector<std::uint8_t> out(std::size_t(height) * (row_bytes + 1));
    parallel_for(0, height, 16, [&](std::int64_t y0, std::int64_t y1) {
        std::array<std::vector<std::uint8_t>, 5> trial;
        for (auto& t : trial) t.resize(row_bytes);
        for (std::int64_t y = y0; y < y1; ++y) {
            const std::uint8_t* row = raw + std::size_t(y) * row_bytes;
            const std::uint8_t* up = y > 0 ? row - row_bytes : nullptr;
            std::array<std::uint64_t, 5> cost{};
            for (std::size_t i = 0; i < row_bytes; ++i) {
                const int x = row[i];
                const int a = i >= std::size_t(bpp) ? row[i - std::size_t(bpp)] : 0;
                const int b = up ? up[i] : 0;
                const int c = up && i >= std::size_t(bpp) ? up[i - std::size_t(bpp)] : 0;
                const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
                const int paeth = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
                const std::uint8_t f[5] = {std::uint8_t(x), std::uint8_t(x - a), std::uint8_t(x - b),
                                           std::uint8_t(x - ((a + b) >> 1)), std::uint8_t(x - paeth)};
                for (int k = 0; k < 5; ++k) {
                    trial[std::size_t(k)][i] = f[k];
                    cost[std::size_t(k)] += std::uint64_t(std::abs(int(std::int8_t(f[k]))));
                }
            }
            const int best = int(std::min_element(cost.begin(), cost.end()) - cost.begin());
            std::uint8_t* dst = out.data() + std::size_t(y) * (row_bytes + 1);
            dst[0] = std::uint8_t(best);
            std::memcpy(dst + 1, trial[std::size_t(best)].data(), row_bytes);
        }
    });
    return out;
}

/// The PNG around a zlib stream `idat` (`size` bytes): signature, IHDR, IDAT chunks of at most `piece`
/// bytes, IEND.
void write_png(std::ostream& file, int width, int height, int bits, int colour_type, const std::uint8_t* idat,
               std::size_t size, std::size_t piece) {
    static constexpr std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    file.write(reinterpret_cast<const char*>(signature), 8);
    std::uint8_t ihdr[13];
    put_u32(ihdr, std::uint32_t(width));
    put_u32(ihdr + 4, std::uint32_t(height));
    ihdr[8] = std::uint8_t(bits);
    ihdr[9] = std::uint8_t(colour_type);
    ihdr[10] = 0;  // deflate
    ihdr[11] = 0;  // adaptive filtering
    ihdr[12] = 0;  // not interlaced
    write_chunk(file, "IHDR", ihdr, sizeof ihdr);
    for (std::size_t at = 0; at < size; at += piece) write_chunk(file, "IDAT", idat + at, std::min(piece, size - at));
    write_chunk(file, "IEND", nullptr, 0);
    if (!file) throw Error("PNG encoding failed: write failed (disk full?)");
}

void encode(std::ostream& file, int width, int height, int bits, int colour_type, int channels, const std::uint8_t* raw,
            int level) {
    if (width <= 0 || height <= 0)
        throw Error("internal error: PNG size " + std::to_string(width) + "x" + std::to_string(height));
    if (level < 0 || level > 12) throw BadInput("PNG compression level must be 0 to 12, got " + std::to_string(level));
    const int bpp = channels * bits / 8;
    const std::size_t row_bytes = std::size_t(width) * std::size_t(bpp);
    const std::vector<std::uint8_t> filtered = filter_rows(raw, height, row_bytes, bpp);
    std::unique_ptr<libdeflate_compressor, decltype(&libdeflate_free_compressor)> z(libdeflate_alloc_compressor(level),
                                                                                    libdeflate_free_compressor);
    if (!z) throw Error("PNG encoding failed: out of memory for the compressor");
    std::vector<std::uint8_t> idat(libdeflate_zlib_compress_bound(z.get(), filtered.size()));
    const std::size_t packed =
        libdeflate_zlib_compress(z.get(), filtered.data(), filtered.size(), idat.data(), idat.size());
    if (packed == 0) throw Error("PNG encoding failed: the compressed image did not fit its bound");

    constexpr std::size_t piece = std::size_t(1) << 20;  // IDAT chunks of 1 MiB, as readers stream them
    write_png(file, width, height, bits, colour_type, idat.data(), packed, piece);
}

/// Level 1 (the fastest), its zlib stream: rows filtered with "Sub" and compressed by zlib at its fastest level in a fixed
/// number of strips on all cores, flushed so that they join into one stream (the bytes do not depend on the
/// thread count). For the textures glTF and tiles embed on every export.
std::vector<std::uint8_t> deflate_rgba_strips(std::span<const std::uint8_t> rgba, int width, int height) {
    const std::size_t stride = std::size_t(width) * 4;
    if (width < 1 || height < 1 || rgba.size() != stride * std::size_t(height))
        throw Error("internal error: encode_rgba_png got " + std::to_string(rgba.size()) + " bytes for " +
                    std::to_string(width) + " x " + std::to_string(height) + " RGBA");
    // Fixed strip count (not the thread count) keeps the output deterministic.
    const int strips = std::min(height, 16);
    std::vector<std::vector<std::uint8_t>> packed(static_cast<std::size_t>(strips));
    std::vector<uLong> adlers(static_cast<std::size_t>(strips));
    std::vector<std::size_t> lengths(static_cast<std::size_t>(strips));
    parallel_for(0, strips, 1, [&](std::int64_t s0, std::int64_t s1) {
        for (std::int64_t s = s0; s < s1; ++s) {
            const int r0 = int(std::int64_t(height) * s / strips), r1 = int(std::int64_t(height) * (s + 1) / strips);
            std::vector<std::uint8_t> filtered(std::size_t(r1 - r0) * (stride + 1));
            std::uint8_t* f = filtered.data();
            for (int r = r0; r < r1; ++r) {
                const std::uint8_t* row = rgba.data() + std::size_t(r) * stride;
                *f++ = 1;  // Sub: each byte minus the same channel of the pixel to its left
                std::memcpy(f, row, 4);
                for (std::size_t i = 4; i < stride; ++i) f[i] = std::uint8_t(row[i] - row[i - 4]);
                f += stride;
            }
            z_stream z{};
            deflateInit2(&z, 1, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY);  // raw deflate, fastest level
            auto& out = packed[std::size_t(s)];
            out.resize(deflateBound(&z, uLong(filtered.size())) + 16);
            z.next_in = filtered.data();
            z.avail_in = uInt(filtered.size());
            z.next_out = out.data();
            z.avail_out = uInt(out.size());
            // Full flush ends each strip byte-aligned with a fresh dictionary, so
            // strips concatenate into one valid stream; only the last finishes it.
            deflate(&z, s + 1 == strips ? Z_FINISH : Z_FULL_FLUSH);
            out.resize(out.size() - z.avail_out);
            deflateEnd(&z);
            adlers[std::size_t(s)] = adler32(1L, filtered.data(), uInt(filtered.size()));
            lengths[std::size_t(s)] = filtered.size();
        }
    });
    std::vector<std::uint8_t> idat = {0x78, 0x01};  // zlib header: deflate, 32 KiB window, fastest
    uLong adler = adlers[0];
    for (std::size_t s = 0; s < packed.size(); ++s) {
        idat.insert(idat.end(), packed[s].begin(), packed[s].end());
        if (s > 0) adler = adler32_combine(adler, adlers[s], z_off_t(lengths[s]));
    }
    std::uint8_t tail[4];
    put_u32(tail, std::uint32_t(adler));
    idat.insert(idat.end(), tail, tail + 4);
    return idat;
}

}  // namespace

GrayImage read_gray_png(const std::filesystem::path& path) { return read_png(read_file(path), path, false); }
GrayImage read_gray_png_header(const std::filesystem::path& path) { return read_png(read_file(path), path, true); }
GrayImage decode_gray_png(const std::vector<std::uint8_t>& bytes, const std::filesystem::path& name, bool header_only) {
    return read_png(bytes, name, header_only);
}

void write_gray_png(std::ostream& file, int width, int height, int bits, std::span<const std::uint16_t> samples,
                    int level) {
    if (bits != 8 && bits != 16) throw Error("internal error: PNG bit depth must be 8 or 16");
    if (samples.size() != std::size_t(width) * std::size_t(height)) throw Error("internal error: PNG sample count");
    std::vector<std::uint8_t> bytes(samples.size() * std::size_t(bits / 8));
    if (bits == 16) {
        for (std::size_t i = 0; i < samples.size(); ++i) {  // PNG stores 16-bit samples big-endian
            bytes[2 * i] = std::uint8_t(samples[i] >> 8);
            bytes[2 * i + 1] = std::uint8_t(samples[i]);
        }
    } else {
        for (std::size_t i = 0; i < samples.size(); ++i) bytes[i] = std::uint8_t(samples[i] > 255 ? 255 : samples[i]);
    }
    encode(file, width, height, bits, 0, 1, bytes.data(), level);
}

void write_rgba_png(std::ostream& file, int width, int height, std::span<const std::uint8_t> rgba, int level) {
    if (rgba.size() != std::size_t(width) * std::size_t(height) * 4) throw Error("internal error: RGBA byte count");
    encode(file, width, height, 8, 6, 4, rgba.data(), level);
}

std::vector<std::uint8_t> encode_rgba_png(std::span<const std::uint8_t> rgba, int width, int height, int level) {
    std::ostringstream out(std::ios::binary);
    if (level == 1) {
        const std::vector<std::uint8_t> idat = deflate_rgba_strips(rgba, width, height);
        write_png(out, width, height, 8, 6, idat.data(), idat.size(), idat.size());  // one IDAT chunk
    } else {
        write_rgba_png(out, width, height, rgba, level);
    }
    const std::string bytes = std::move(out).str();
    return {bytes.begin(), bytes.end()};
}

}  // namespace orogen
