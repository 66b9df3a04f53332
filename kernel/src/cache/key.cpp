// key.cpp — node keys (a Merkle chain over the graph) and the build identity of the binaries they hash.

#include "entry.hpp"

#include <orogen/plugin.hpp>

#include <bit>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <elf.h>
#include <fcntl.h>
#include <link.h>
#include <map>
#include <mutex>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen::cache {

std::string hex(const Digest& d) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (std::uint8_t b : d) {
        s += digits[b >> 4];
        s += digits[b & 15];
    }
    return s;
}

Hasher& Hasher::bytes(const void* data, std::size_t n) {
    sha_.update(data, n);
    return *this;
}
Hasher& Hasher::u64(std::uint64_t v) { return bytes(&v, sizeof v); }
Hasher& Hasher::f64(double v) { return u64(std::bit_cast<std::uint64_t>(v)); }
Hasher& Hasher::text(std::string_view s) {
    u64(s.size());
    return bytes(s.data(), s.size());
}

namespace {
void hash_params(Hasher& h, const std::map<std::string, ParamValue, std::less<>>& params);
}  // namespace

Digest node_key(const Plan& plan, const PlannedNode& node, const std::vector<std::optional<Digest>>& inputs,
                std::string_view plugin_name, std::string_view plugin_version, std::string_view plugin_identity,
                std::uint64_t seed) {
    Hasher h;
    h.text("orogen node key")
        .u64(format_version)
        .text(OROGEN_VERSION)
        .u64(OROGEN_PLUGIN_API_VERSION)
        .text(kernel_identity());
    h.text(node.node->qualified_name()).text(plugin_name).text(plugin_version).text(plugin_identity);
    h.u64(seed);
    h.u64(std::uint64_t(plan.grid.width)).u64(std::uint64_t(plan.grid.height)).f64(plan.grid.cell);
    h.u64(std::uint64_t(std::int64_t(node.mapped_input) + 1));
    hash_params(h, node.params);
    // A loop node's body: each process's name, label and parameters, in order.
    h.u64(node.processes.size());
    for (const auto& process : node.processes) {
        h.text(process.process->name).text(process.label);
        hash_params(h, process.params);
    }
    h.u64(inputs.size());
    for (const auto& in : inputs) {
        h.u64(in ? 1 : 0);
        if (in) h.digest(*in);
    }
    return h.finish();
}

namespace {
void hash_params(Hasher& h, const std::map<std::string, ParamValue, std::less<>>& params) {
    h.u64(params.size());
    for (const auto& [name, value] : params) {
        h.text(name).u64(value.index());
        std::visit(
            [&](const auto& x) {
                using T = std::decay_t<decltype(x)>;
                if constexpr (std::is_same_v<T, std::monostate>) {
                } else if constexpr (std::is_same_v<T, std::int64_t>) h.u64(std::uint64_t(x));
                else if constexpr (std::is_same_v<T, double>) h.f64(x);
                else if constexpr (std::is_same_v<T, bool>) h.u64(x ? 1 : 0);
                else if constexpr (std::is_same_v<T, std::string>) h.text(x);
                else if constexpr (std::is_same_v<T, Point2>) h.f64(x.x).f64(x.y);
                else {
                    h.u64(x.size());
                    for (const auto& p : x) h.f64(p.x).f64(p.y);
                }
            },
            value);
    }
}

struct FoundBinary {
    const void* address = nullptr;
    bool found = false;
    std::string file;  ///< "" for the main program
    std::string build_id;  ///< hex, "" if it has none
};

/// The GNU build-id in a PT_NOTE segment mapped at `notes` (`size` bytes, entries aligned to `align`).
std::string build_id_in(const std::uint8_t* notes, std::size_t size, std::size_t align) {
    align = align < 4 ? 4 : align;
    auto up = [align](std::size_t n) { return (n + align - 1) / align * align; };
    std::size_t at = 0;
    while (at + sizeof(ElfW(Nhdr)) <= size) {
        ElfW(Nhdr) n;
        std::memcpy(&n, notes + at, sizeof n);
        const std::size_t name_at = at + sizeof n, desc_at = name_at + up(n.n_namesz);
        if (desc_at > size || n.n_descsz > size - desc_at) break;
        if (n.n_type == NT_GNU_BUILD_ID && n.n_namesz == 4 && std::memcmp(notes + name_at, "GNU", 4) == 0 &&
            n.n_descsz > 0) {
            static const char* digits = "0123456789abcdef";
            std::string hexid;
            for (std::size_t i = 0; i < n.n_descsz; ++i) {
                hexid += digits[notes[desc_at + i] >> 4];
                hexid += digits[notes[desc_at + i] & 15];
            }
            return hexid;
        }
        at = desc_at + up(n.n_descsz);
    }
    return {};
}

int find_binary(dl_phdr_info* info, std::size_t, void* data) {
    auto* want = static_cast<FoundBinary*>(data);
    const auto addr = reinterpret_cast<std::uintptr_t>(want->address);
    bool holds = false;
    for (int i = 0; i < info->dlpi_phnum && !holds; ++i) {
        const auto& ph = info->dlpi_phdr[i];
        const std::uintptr_t begin = info->dlpi_addr + ph.p_vaddr;
        holds = ph.p_type == PT_LOAD && addr >= begin && addr < begin + ph.p_memsz;
    }
    if (!holds) return 0;
    want->found = true;
    want->file = info->dlpi_name ? info->dlpi_name : "";
    for (int i = 0; i < info->dlpi_phnum && want->build_id.empty(); ++i) {
        const auto& ph = info->dlpi_phdr[i];
        if (ph.p_type == PT_NOTE)
            want->build_id = build_id_in(reinterpret_cast<const std::uint8_t*>(info->dlpi_addr + ph.p_vaddr),
                                         ph.p_memsz, std::size_t(ph.p_align));
    }
    return 1;
}

std::optional<Digest> sha256_of_file(const fs::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    Hasher h;
    std::vector<std::uint8_t> buf(std::size_t(1) << 20);
    bool ok = true;
    for (;;) {
        const ssize_t n = ::read(fd, buf.data(), buf.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) ok = false;
        if (n <= 0) break;
        h.bytes(buf.data(), std::size_t(n));
    }
    ::close(fd);
    if (!ok) return std::nullopt;
    return h.finish();
}
}  // namespace

std::string binary_identity(const void* address) {
    FoundBinary want;
    want.address = address;
    ::dl_iterate_phdr(find_binary, &want);
    if (!want.found) return {};
    if (!want.build_id.empty()) return "build-id:" + want.build_id;
    // No build-id (linked with --build-id=none): the file's bytes, once per file and process.
    static std::mutex mutex;
    static std::map<std::string, std::string> known;
    const std::string file = want.file.empty() ? std::string("/proc/self/exe") : want.file;
    std::lock_guard lock(mutex);
    if (const auto it = known.find(file); it != known.end()) return it->second;
    const auto digest = sha256_of_file(file);
    return known[file] = digest ? "sha256:" + hex(*digest) : std::string();
}

const std::string& kernel_identity() {
    static const std::string identity = [] {
        const std::string id = binary_identity(reinterpret_cast<const void*>(&kernel_identity));
        // Without one, a kernel rebuilt with other code must not find this one's entries: this process's own.
        return id.empty() ? "process:" + std::to_string(::getpid()) + "-" +
                std::to_string(std::chrono::steady_clock::now().time_since_epoch().count())
                          : id;
    }();
    return identity;
}

Digest output_key(const Digest& node, std::string_view name) {
    Hasher h;
    h.text("orogen output").digest(node).text(name);
    return h.finish();
}

Digest content_key(const Digest& node, std::string_view name, const Digest& content) {
    Hasher h;
    h.text("orogen content").digest(node).text(name).digest(content);
    return h.finish();
}

Digest bound_key(const Digest& content) {
    Hasher h;
    h.text("orogen bound value").digest(content);
    return h.finish();
}

}  // namespace orogen::cache
