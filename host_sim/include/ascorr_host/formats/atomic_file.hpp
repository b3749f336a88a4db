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
// - Errors name the output as the user gave it (with its option, when the
//   output has one), not its temporary file. Every write is checked, and so is
//   the flush of standard output.
//
// OutputSet: all the outputs of one run, committed together or not at all.
// - Declared before the run's work: its constructor refuses an output that is
//   an input (refuse_output_over_input) and then opens every output (creates
//   its temporary file, or opens the stream), so that an unusable path (a
//   missing folder, a directory, no permission) fails at once, before any input
//   is read. Two outputs that are the same file or stream are refused, whatever
//   their kind (same device and inode after opening: "-", /dev/stdout and
//   /dev/fd/1 into one pipe; the same canonical path for files not there yet);
//   only the null device may take several.
// - commit() first completes every output: the streams flushed (a stream's
//   bytes are written in place as the run goes and cannot be taken back), the
//   temporary files flushed, fsync'ed and closed. Any failure there throws and
//   nothing is renamed: every existing output is left as it was. Only then are
//   the temporary files renamed over their outputs, in the order declared.
// - A cleanup signal (SIGINT, SIGTERM, SIGHUP, SIGPIPE) that comes during the
//   renames, in any thread, is deferred until the last rename and then acts
//   (the process ends by it, its outputs complete): the renames are all or none
//   for every signal a process can catch. SIGKILL or a crash during the renames
//   (a few rename() calls) can leave the first outputs new and the rest old;
//   the rest's complete temporary files are then still beside them
//   (OUT.tmp-PID-XXXXXXXX): a leftover temporary file is the sign of a set cut
//   short, and renaming it over its output completes the set (recovery rule).
//   The same holds when a rename itself fails after others succeeded: the
//   message names the outputs replaced and those left, and keeps the latter's
//   temporary files.
// - Adding an output to a command is one entry in its list of outputs (e.g.
//   correct_outputs() in correct_file.hpp) and writes into outputs["--opt"]:
//   the checks, the early opening and the joint commit come with it.
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

#include <sys/stat.h>
#include <sys/types.h>

#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace ascorr::host {

class AtomicFile {
public:
    // option: how messages name the output ("--out"); may be empty.
    explicit AtomicFile(std::string target, std::string option = "");
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    void write(std::string_view data);
    // complete(), then install(): one file on its own.
    void commit();
    // Flushes; a temporary file is also fsync'ed and closed. Throws on failure.
    void complete();
    // Renames the completed temporary file over the output (nothing for a stream).
    void install();
    // After a failed commit of a set: the completed temporary file stays, for
    // the recovery rule above (the destructor leaves it).
    void keep_temporary() noexcept;
    // True when the output is written in place (standard output, a device, a FIFO).
    bool streamed() const noexcept { return temp_.empty(); }
    // The output as messages name it ("--out x.csv", or "x.csv").
    std::string name() const;
    const std::string& temporary() const noexcept { return temp_; }

    // What the output is, to tell two outputs apart: the device and inode of
    // the open stream or of the existing file, else the canonical path.
    struct Identity {
        bool has_inode = false;
        dev_t dev = 0;
        ino_t ino = 0;
        bool null_device = false;  // /dev/null: any number of outputs may go there
        std::string path;          // canonical, for a regular file (existing or not)
    };
    Identity identity() const;

private:
    [[noreturn]] void fail(const std::string& what) const;
    void open_temporary(const struct ::stat* existing);

    std::string target_;  // as given, for messages
    std::string option_;  // for messages; may be empty
    std::string real_;    // the final target of the symbolic links
    std::string temp_;    // empty when streamed
    std::FILE* f_ = nullptr;
    int cleanup_slot_ = -1;
    bool completed_ = false;
    bool committed_ = false;
    bool kept_ = false;
};

// Writes a whole small file atomically.
void write_file_atomically(const std::string& path, std::string_view data);

// An option and its path, for messages ("--in", "x.csv").
struct NamedPath {
    std::string option;
    std::string path;
};

// A command's report on standard output, as an output of its OutputSet.
inline const NamedPath kStandardOutput{"standard output", "-"};

// The outputs of one run (see the top of this file).
class OutputSet {
public:
    // Refuses an output that is one of inputs, then opens every output and
    // refuses two that are one file. Throws std::runtime_error; nothing is
    // left behind then.
    explicit OutputSet(std::vector<NamedPath> outputs, const std::vector<NamedPath>& inputs = {});
    OutputSet(OutputSet&&) noexcept = default;
    OutputSet& operator=(OutputSet&&) noexcept = default;
    ~OutputSet() = default;  // uncommitted: each AtomicFile removes its temporary file

    // The output of that option (std::logic_error when none was declared).
    AtomicFile& operator[](std::string_view option);
    bool has(std::string_view option) const noexcept;
    // Completes every output, then renames every temporary file (see above).
    void commit();

private:
    std::vector<NamedPath> names_;
    std::vector<std::unique_ptr<AtomicFile>> files_;
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
