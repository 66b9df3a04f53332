// orogen/io.hpp — writing files so that a failed run loses nothing.
//
// Every output goes to a temporary name beside its target and is renamed over
// it only once it is complete (rename(2) is atomic within a folder), so a run
// that fails half way never leaves a half-written file and never clobbers a
// good one. Formats that are several files (.gltf + .bin, .pvd + .vtp...) use
// one AtomicFile each and commit them together with commit_all().
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace orogen {

class AtomicFile;
void commit_all(std::span<AtomicFile*> files);

class AtomicFile {
public:
    /// Prepare to write `target`. Throws orogen::Error (failed_run) if the
    /// temporary file cannot be created, naming the folder and the reason.
    explicit AtomicFile(std::filesystem::path target);
    ~AtomicFile();  ///< removes the temporary file unless committed
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    AtomicFile(AtomicFile&&) noexcept;

    const std::filesystem::path& target() const { return target_; }
    /// The temporary file: hand it to a library that writes by file name.
    const std::filesystem::path& temporary() const { return temporary_; }
    /// A stream on the temporary file (binary). What goes through it in order
    /// is hashed (SHA-256) on the way, so the run's manifest need not read the
    /// file again; a seek other than tellp() voids that (sha256_file() then
    /// reads it), as does writing the temporary file by name. To hand the file
    /// to a library that writes by name, close() the stream before anything is
    /// written through it; after writing, leave closing to commit().
    std::ofstream& stream();
    void write(std::span<const std::uint8_t> bytes);
    /// Flush, fsync and rename over the target. Throws orogen::Error on failure
    /// (disk full, folder gone...); the target is then untouched.
    void commit();
    bool committed() const { return committed_; }

    class Hashing;  ///< the stream's buffer: SHA-256 of what passes (io.cpp)

private:
    friend void commit_all(std::span<AtomicFile*> files);
    void install_hashing();
    void flush_checked();  ///< flush, close and fsync the temporary file; throws orogen::Error
    std::filesystem::path target_;
    std::filesystem::path temporary_;
    std::unique_ptr<Hashing> hashing_;  // before stream_: the stream, which points at it, goes first
    std::ofstream stream_;
    std::string digest_;  ///< set while committing when every byte went through stream() in order
    bool committed_ = false;
};

/// Commit several files together: all are flushed first, so a failure while
/// flushing leaves every target untouched.
void commit_all(std::span<AtomicFile*> files);

/// Write `bytes` to `target` atomically.
void write_file_atomically(const std::filesystem::path& target, std::span<const std::uint8_t> bytes);

/// Read a whole file; throws orogen::BadInput naming the file if it cannot be read, or if it is not a
/// regular file (a FIFO or a device would hang or never end).
std::vector<std::uint8_t> read_file(const std::filesystem::path& path);

/// "" if `path` names a regular file (symbolic links followed) that can be read, else why not, in words
/// that follow the path: "is a folder; give a file", "is a FIFO, not a regular file; ...".
std::string regular_file_problem(const std::filesystem::path& path);

// ------------------------------------------------------------ memory budget
//
// One rule for every heightmap a spec or a file asks for: at most a quarter of
// physical memory for one heightmap (4 bytes a vertex), checked before anything
// is allocated. The checker applies it to the grid, each reader to the size its
// file declares.

/// Physical memory, bytes (8 GiB if it cannot be found out).
std::uint64_t physical_memory();
/// A quarter of physical memory, bytes.
std::uint64_t heightmap_memory_limit();
/// "" if a width × height heightmap fits in `limit` bytes (0: heightmap_memory_limit()), else the rest of
/// a sentence: "needs 37.3 GiB for one heightmap (4 bytes a vertex), more than the 5.9 GiB allowed here (a
/// quarter of this machine's 23.5 GiB of memory); use at most about 39000x39000".
std::string heightmap_memory_problem(double width, double height, std::uint64_t limit = 0);
/// "3.6 TiB", "512 MiB".
std::string human_bytes(double bytes);

/// SHA-256 of a file as 64 lowercase hex digits (as `sha256sum` prints it). A file an AtomicFile
/// committed after writing it only through stream() is not read again: its digest was taken while it
/// was written, and stands while the file's inode, size and times are unchanged.
std::string sha256_file(const std::filesystem::path& path);
std::string sha256_hex(std::span<const std::uint8_t> bytes);

// ---------------------------------------------------------------- PNG codec

/// A decoded grayscale PNG: `bits` 8 or 16, samples row-major, 0..255 or 0..65535.
struct GrayImage {
    int width = 0, height = 0;
    int bits = 8;
    std::vector<std::uint16_t> samples;
};

/// Decode a grayscale PNG (colour type 0, or 4 with alpha ignored). Throws
/// orogen::BadInput naming the file for anything else: not a PNG, truncated,
/// colour, palette.
GrayImage read_gray_png(const std::filesystem::path& path);
/// Read only the header: size and bit depth, same checks as read_gray_png minus decoding (the declared size
/// against the memory budget, the chunks complete, enough image data for the size).
GrayImage read_gray_png_header(const std::filesystem::path& path);
/// read_gray_png (or _header) on bytes already in memory; `name` is only for messages.
GrayImage decode_gray_png(const std::vector<std::uint8_t>& bytes, const std::filesystem::path& name, bool header_only);

/// Encode a grayscale PNG (8 or 16 bits) to `file` (usually AtomicFile::stream()). `level` is libdeflate's
/// compression level, 0 (stored) to 12 (smallest, slowest); 6 gives libpng's default size about twice as fast.
void write_gray_png(std::ostream& file, int width, int height, int bits, std::span<const std::uint16_t> samples,
                    int level = 6);
/// Encode an 8-bit RGBA PNG.
void write_rgba_png(std::ostream& file, int width, int height, std::span<const std::uint8_t> rgba, int level = 6);
/// An RGBA PNG in memory (the one RGBA encoder: exporters' files and the textures glTF and tiles embed).
/// Level 1 is the fastest: "Sub"-filtered rows in 16 strips deflated in parallel (zlib); the other levels
/// are write_rgba_png's bytes (adaptive filters, libdeflate).
std::vector<std::uint8_t> encode_rgba_png(std::span<const std::uint8_t> rgba, int width, int height, int level = 6);

}  // namespace orogen
