// ascorr_host/formats/atomic_file.hpp: output files that never destroy data.
//
// The one place where every `ascorr` command decides how to write an output:
//
// - A regular file (or a path that does not exist yet) is written all or
//   nothing: into a temporary file beside it, flushed, then renamed over it,
//   which POSIX makes atomic. If commit() is never reached (an error, an
//   exception, a signal), the temporary file is removed and an existing output
//   is left as it was. An existing output keeps its permission bits (and, for
//   root, its owner).
// - The temporary file is OUT.tmp-PID-XXXXXXXX (eight random letters and
//   digits), created with O_CREAT|O_EXCL|O_NOFOLLOW: always a new file of this
//   run, never an existing file of that name (an input, a link), which is
//   neither truncated, renamed nor removed; a name that exists is passed over
//   for another (64 tries, then the output is refused).
// - A path reached through symbolic links replaces the links' final target and
//   keeps the links (the chain is followed by readlink, at most 40 hops, also
//   when the final target does not exist yet).
// - "-" is standard output. Anything that is not a regular file (a FIFO, a
//   character device such as /dev/null, a socket) and every path under /dev/
//   or /proc/ (e.g. /dev/stdout) is written in place as a stream, never renamed
//   over. A directory is refused.
// - Errors name the output as the user gave it, not its temporary file.
//
// refuse_output_over_input() checks, before anything is read, that no output is
// one of the command's inputs (same device and inode: it sees through other
// paths, symbolic and hard links).
//
// install_signal_cleanup() makes SIGINT, SIGTERM, SIGHUP and SIGPIPE remove
// every registered temporary file and folder and kill every registered child
// process, then re-raise the signal with its default action, so that the
// process ends by that signal (a shell reports 128 + signal). Signals ignored
// at start (nohup) stay ignored. The handler only calls async-signal-safe
// functions (unlink, rmdir, kill, waitpid, sigaction, raise) on a fixed table.
#pragma once

#include <csignal>

#include <sys/types.h>

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace ascorr::host {

class AtomicFile {
public:
    explicit AtomicFile(std::string target);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    void write(std::string_view data);
    void commit();
    // True when the output is written in place (standard output, a device, a FIFO).
    bool streamed() const noexcept { return temp_.empty(); }

private:
    [[noreturn]] void fail(const std::string& what) const;

    std::string target_;  // as given, for messages
    std::string real_;    // the final target of the symbolic links
    std::string temp_;    // empty when streamed
    std::FILE* f_ = nullptr;
    int cleanup_slot_ = -1;
    bool committed_ = false;
};

// Writes a whole small file atomically.
void write_file_atomically(const std::string& path, std::string_view data);

// An option and its path, for messages ("--in", "x.csv").
struct NamedPath {
    std::string option;
    std::string path;
};
// Throws std::runtime_error when an output (or standard output, when
// check_stdout) is the same file as an input, or when two outputs are the same
// file. Paths that do not exist yet cannot be any input; "-" is standard output.
void refuse_output_over_input(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs,
                              bool check_stdout = false);

// Throws std::runtime_error when two outputs name the same file, whether it
// exists or not (the same text, or the same canonical path): "<second> is also
// <first>: the two files need two paths".
void refuse_same_output(const NamedPath& first, const NamedPath& second);

// Installs the handlers of SIGINT, SIGTERM, SIGHUP and SIGPIPE (once; call it
// from main before any thread starts).
void install_signal_cleanup();

// Holds the cleanup signals (SIGINT, SIGTERM, SIGHUP, SIGPIPE) in this
// thread while it lives, so that a child started and then registered
// (cleanup_register_child) cannot be missed by a signal that comes between
// the two: the signal waits, and its handler finds the child in the table.
// A child takes previous() as its mask (posix_spawnattr_setsigmask, or
// pthread_sigmask after fork), so that it does not inherit the hold.
class CleanupSignalsHeld {
public:
    CleanupSignalsHeld() noexcept;
    ~CleanupSignalsHeld();
    CleanupSignalsHeld(const CleanupSignalsHeld&) = delete;
    CleanupSignalsHeld& operator=(const CleanupSignalsHeld&) = delete;
    const sigset_t& previous() const noexcept { return previous_; }

private:
    sigset_t previous_{};
};

// Registers what the signal handler removes or kills; each returns a slot to
// release when the thing is gone or committed. Throws when the table is full
// or a path is longer than PATH_MAX.
int cleanup_register_file(const std::string& path);
int cleanup_register_folder(const std::string& path);  // removed (rmdir) after the files
int cleanup_register_child(pid_t pid);                 // SIGKILL, then reaped
void cleanup_release(int slot) noexcept;

}  // namespace ascorr::host
