// Output files written whole or not at all: a temporary file renamed into place, removed again
// if the process is interrupted while writing it; `-` written to standard output's descriptor.
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "rtcost/io.hpp"

namespace rtcost {
namespace {

/// Where `-` is written (set_standard_output_descriptor).
std::atomic<int> g_stdout_fd{STDOUT_FILENO};

/// The temporary file being written, for the signal handler to remove: a fixed buffer, as a
/// handler may not allocate, published by a lock-free flag (the signal may be handled on another
/// thread). One slot: a program writes one output at a time (the CLI does; a library user
/// writing several at once from threads has the last one's temporary removed).
char g_pending[4096];
std::atomic<int> g_has_pending{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void remove_pending_and_reraise(int sig) {
    const int saved = errno;
    if (g_has_pending.load(std::memory_order_acquire)) ::unlink(g_pending);
    errno = saved;
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    ::sigaction(sig, &dfl, nullptr);
    ::raise(sig);
}

/// Registers `tmp` as the file to remove if a signal ends the process while it is written.
class PendingFile {
public:
    explicit PendingFile(const std::filesystem::path& tmp) {
        const std::string s = tmp.string();
        if (s.size() < sizeof g_pending) {
            g_has_pending.store(0, std::memory_order_release);
            std::memcpy(g_pending, s.c_str(), s.size() + 1);
            g_has_pending.store(1, std::memory_order_release);
        }
    }
    ~PendingFile() { g_has_pending.store(0, std::memory_order_release); }
    PendingFile(const PendingFile&) = delete;
    PendingFile& operator=(const PendingFile&) = delete;
};

/// All of `bytes` onto descriptor `fd` (a pipe takes them in pieces).
bool write_all(int fd, std::string_view bytes) {
    while (!bytes.empty()) {
        const ssize_t n = ::write(fd, bytes.data(), bytes.size());
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        bytes.remove_prefix(static_cast<std::size_t>(n));
    }
    return true;
}

/// Writes to an existing non-regular file (device, pipe) without replacing it.
void write_in_place(const std::string& path, const std::string& target, std::string_view bytes) {
    std::FILE* f = std::fopen(target.c_str(), "wb");
    if (!f) throw InputError(path, 0, "cannot open for writing (" + std::string(std::strerror(errno)) + ")");
    const std::size_t put = std::fwrite(bytes.data(), 1, bytes.size(), f);
    const bool ok = put == bytes.size() && std::fflush(f) == 0;
    const int err = errno;
    std::fclose(f);
    if (!ok) throw InputError(path, 0, "write failed (" + std::string(std::strerror(err)) + ")");
}

}  // namespace

void set_standard_output_descriptor(int fd) { g_stdout_fd = fd; }

void remove_output_on_signals() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
        // A signal the parent ignores (nohup's SIGHUP, a script's background SIGINT, SIGPIPE)
        // stays ignored, for this process and what it runs.
        struct sigaction old {};
        if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;
        struct sigaction act {};
        act.sa_handler = remove_pending_and_reraise;
        sigemptyset(&act.sa_mask);
        ::sigaction(sig, &act, nullptr);
    }
}

void write_file_atomic(const std::string& path, std::string_view bytes) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (path.empty()) throw InputError("output", 0, "empty output path");
    if (path == "-") {
        // Not through /dev/stdout: opening it truncates a file the shell redirected to, over
        // what was written to it before.
        std::fflush(stdout);
        if (!write_all(g_stdout_fd, bytes))
            throw InputError(path, 0, "write to standard output failed (" + std::string(std::strerror(errno)) + ")");
        return;
    }
    // Through a symbolic link: the file it points to is what the user named.
    fs::path target = fs::weakly_canonical(fs::path(path), ec);
    if (ec) target = fs::path(path);
    const fs::file_status st = fs::status(target, ec);
    if (fs::is_directory(st)) throw InputError(path, 0, "is a directory; give a file name for the output");
    // A device, a pipe or a socket is written in place: renaming over it would replace it.
    if (fs::exists(st) && !fs::is_regular_file(st)) return write_in_place(path, target.string(), bytes);
    fs::path tmp = target;
    tmp += ".tmp." + std::to_string(::getpid());
    const PendingFile pending(tmp);
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError(path, 0, "cannot open for writing (" + std::string(std::strerror(errno)) + ")");
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.flush();
        if (!out) {
            out.close();
            fs::remove(tmp, ec);
            throw InputError(path, 0, "write failed (disk full?)");
        }
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        const std::string why = ec.message();
        fs::remove(tmp, ec);
        throw InputError(path, 0, "cannot move output into place: " + why);
    }
}

}  // namespace rtcost
