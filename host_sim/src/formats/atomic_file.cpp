#include "ascorr_host/formats/atomic_file.hpp"

#include <filesystem>

#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <random>
#include <stdexcept>

namespace ascorr::host {

namespace {

// ---- the signal-cleanup table -------------------------------------------
// Fixed storage, no allocation: the handler reads it while the program may be
// anywhere. A slot is claimed (kClaimed) by one thread, filled, then published
// with its kind (release); the handler acts on published slots only.
enum SlotState : int { kFree = 0, kClaimed, kFile, kFolder, kChild };
struct Slot {
    std::atomic<int> state{kFree};
    pid_t pid = 0;
    char path[PATH_MAX] = {};
};
constexpr std::size_t kSlots = 32;  // plot, the busiest command, needs 9
std::array<Slot, kSlots> g_slots;
constexpr std::array<int, 4> kCleanupSignals = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

int claim(SlotState kind, const std::string& path, pid_t pid) {
    if (path.size() >= PATH_MAX) {
        throw std::runtime_error(path + ": path longer than PATH_MAX");
    }
    for (std::size_t i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (g_slots[i].state.compare_exchange_strong(expected, kClaimed, std::memory_order_acq_rel)) {
            std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
            g_slots[i].pid = pid;
            g_slots[i].state.store(kind, std::memory_order_release);
            return static_cast<int>(i);
        }
    }
    throw std::runtime_error("too many temporary files or child processes at once (" + std::to_string(kSlots) + ")");
}

void run_cleanup() noexcept {
    for (Slot& s : g_slots) {  // children first: they may still be writing
        if (s.state.load(std::memory_order_acquire) == kChild) {
            ::kill(s.pid, SIGKILL);
            ::waitpid(s.pid, nullptr, 0);
        }
    }
    for (Slot& s : g_slots) {
        if (s.state.load(std::memory_order_acquire) == kFile) {
            ::unlink(s.path);
        }
    }
    for (std::size_t i = kSlots; i-- > 0;) {  // folders after their files
        if (g_slots[i].state.load(std::memory_order_acquire) == kFolder) {
            ::rmdir(g_slots[i].path);
        }
    }
}

// The commit of an OutputSet and the handler exclude each other: whichever
// moves the phase from kIdle first goes on. A signal during the renames is
// noted (g_deferred) and raised again by the commit after its last rename; a
// commit that finds the cleanup under way waits for the end of the process.
enum Phase : int { kIdle = 0, kCommitting, kCleaning };
std::atomic<int> g_phase{kIdle};
std::atomic<int> g_deferred{0};

extern "C" void on_cleanup_signal(int sig) {
    g_deferred.store(sig);  // before the exchange: a commit ending now sees it
    int idle = kIdle;
    if (!g_phase.compare_exchange_strong(idle, kCleaning)) {
        return;  // a commit is renaming (it raises sig when done), or another thread is cleaning up
    }
    run_cleanup();
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    ::sigemptyset(&dfl.sa_mask);
    ::sigaction(sig, &dfl, nullptr);
    sigset_t set;
    ::sigemptyset(&set);
    ::sigaddset(&set, sig);
    ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
    ::raise(sig);  // default action: the process ends by this signal
}

// While it lives, the cleanup signals wait (see Phase).
class CommitWindow {
public:
    CommitWindow() noexcept {
        int idle = kIdle;
        while (!g_phase.compare_exchange_strong(idle, kCommitting)) {
            ::pause();  // a handler is cleaning up: the process ends by its signal
            idle = kIdle;
        }
    }
    ~CommitWindow() {
        g_phase.store(kIdle);
        if (const int sig = g_deferred.exchange(0); sig != 0) {
            ::raise(sig);  // the handler now runs as it would have: outputs complete, the process ends
        }
    }
    CommitWindow(const CommitWindow&) = delete;
    CommitWindow& operator=(const CommitWindow&) = delete;
};

// ---- paths ---------------------------------------------------------------

bool special_path(const std::string& p) {
    return p.rfind("/dev/", 0) == 0 || p.rfind("/proc/", 0) == 0;
}

// Follows a chain of symbolic links to its end (which need not exist).
// special: set when the chain passes through /dev/ or /proc/.
std::string final_target(const std::string& path, bool& special) {
    std::string p = path;
    special = special_path(p);
    if (special) {
        return path;
    }
    for (int hop = 0; hop < 40; ++hop) {
        struct stat ls {};
        if (::lstat(p.c_str(), &ls) != 0 || !S_ISLNK(ls.st_mode)) {
            return p;
        }
        std::array<char, PATH_MAX> buf{};
        const ssize_t n = ::readlink(p.c_str(), buf.data(), buf.size() - 1);
        if (n < 0) {
            return p;
        }
        const std::string link(buf.data(), static_cast<std::size_t>(n));
        if (link.empty() || link[0] == '/') {
            p = link;
        } else {
            const std::size_t slash = p.rfind('/');
            p = slash == std::string::npos ? link : p.substr(0, slash + 1) + link;
        }
        special = special || special_path(p);
        if (special) {  // /proc's links name pipes and sockets as "pipe:[n]": let open() follow them
            return path;
        }
    }
    errno = ELOOP;
    throw std::runtime_error(path + ": cannot write the output: " + std::strerror(errno));
}

bool is_null_device(const std::string& path) {
    struct stat st {};
    struct stat null {};
    return ::stat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode) && ::stat("/dev/null", &null) == 0 &&
           st.st_rdev == null.st_rdev;
}

// Eight random letters and digits: with the pid, a name no other run picks.
std::string random_suffix() {
    static constexpr char kChars[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    std::random_device rd;
    std::string s(8, '0');
    for (char& c : s) {
        c = kChars[rd() % (sizeof kChars - 1)];
    }
    return s;
}

// Creates REAL.tmp-PID-XXXXXXXX as a new file (O_EXCL: never an existing file
// of that name, which is left alone) and registers it for the signal cleanup in
// one step (the signals held: none can find it created and not registered).
// Returns the descriptor, or -1 with errno (EEXIST when every name was taken).
int create_temporary(const std::string& real, std::string& temp, int& slot) {
    constexpr int kTries = 64;
    for (int i = 0; i < kTries; ++i) {
        std::string name = real + ".tmp-" + std::to_string(::getpid()) + "-" + random_suffix();
        const CleanupSignalsHeld held;
        const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd < 0) {
            if (errno == EEXIST) {
                continue;
            }
            return -1;
        }
        try {
            slot = cleanup_register_file(name);
        } catch (...) {
            ::close(fd);
            ::unlink(name.c_str());
            throw;
        }
        temp = std::move(name);
        return fd;
    }
    errno = EEXIST;
    return -1;
}

}  // namespace

// ---- AtomicFile ------------------------------------------------------------

std::string AtomicFile::name() const {
    if (target_ == "-") {
        return option_.empty() || option_ == kStandardOutput.option ? kStandardOutput.option
                                                                    : option_ + " - (standard output)";
    }
    return option_.empty() ? target_ : option_ + " " + target_;
}

void AtomicFile::fail(const std::string& what) const {
    throw std::runtime_error(name() + ": " + what + ": " + std::strerror(errno));
}

AtomicFile::AtomicFile(std::string target, std::string option)
    : target_(std::move(target)), option_(std::move(option)) {
    if (target_ == "-") {
        f_ = stdout;
        return;
    }
    bool special = false;
    real_ = final_target(target_, special);
    struct stat st {};
    const bool exists = ::stat(real_.c_str(), &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) {
        throw std::runtime_error(name() + ": is a directory: the output must be a file");
    }
    if (special || (exists && !S_ISREG(st.st_mode))) {  // a stream: written in place
        f_ = std::fopen(real_.c_str(), "wb");
        if (f_ == nullptr) {
            fail("cannot open the output");
        }
        return;
    }
    open_temporary(exists ? &st : nullptr);
}

void AtomicFile::open_temporary(const struct ::stat* existing) {
    const int fd = create_temporary(real_, temp_, cleanup_slot_);
    if (fd < 0) {
        fail("cannot create a temporary file beside the output");
    }
    if (existing != nullptr) {  // keep the output's permissions (and owner, when we may)
        (void)::fchmod(fd, existing->st_mode & 07777);
        if (::geteuid() == 0) {
            (void)::fchown(fd, existing->st_uid, existing->st_gid);
        }
    }
    f_ = ::fdopen(fd, "wb");
    if (f_ == nullptr) {
        ::close(fd);
        fail("cannot write the output");
    }
}

AtomicFile::~AtomicFile() {
    if (f_ != nullptr && f_ != stdout) {
        std::fclose(f_);
    }
    if (!committed_ && !kept_ && !temp_.empty()) {
        ::unlink(temp_.c_str());
    }
    if (cleanup_slot_ >= 0) {
        cleanup_release(cleanup_slot_);
    }
}

void AtomicFile::write(std::string_view data) {
    if (std::fwrite(data.data(), 1, data.size(), f_) != data.size()) {
        fail("write failed");
    }
}

void AtomicFile::complete() {
    if (completed_) {
        return;
    }
    if (f_ == stdout && std::ferror(stdout) != 0) {  // a write by another path (printf, iostream) failed
        throw std::runtime_error(name() + ": write failed (an earlier write to it failed)");
    }
    if (std::fflush(f_) != 0) {
        fail("write failed");
    }
    if (f_ == stdout) {
        completed_ = true;
        return;
    }
    if (!temp_.empty() && ::fsync(::fileno(f_)) != 0) {
        fail("write failed");
    }
    const int rc = std::fclose(f_);
    f_ = nullptr;
    if (rc != 0) {
        fail("close failed");
    }
    completed_ = true;
}

void AtomicFile::install() {
    if (!completed_) {
        throw std::logic_error(name() + ": install() before complete()");
    }
    if (!temp_.empty() && std::rename(temp_.c_str(), real_.c_str()) != 0) {
        fail("cannot rename the temporary file into place");
    }
    committed_ = true;
    cleanup_release(cleanup_slot_);  // its name is gone: nothing for a signal to remove
    cleanup_slot_ = -1;
}

void AtomicFile::commit() {
    complete();
    install();
}

void AtomicFile::keep_temporary() noexcept {
    kept_ = true;
    cleanup_release(cleanup_slot_);  // a signal must not remove it either
    cleanup_slot_ = -1;
}

AtomicFile::Identity AtomicFile::identity() const {
    Identity id;
    struct stat st {};
    const bool has = f_ != nullptr && temp_.empty() ? ::fstat(::fileno(f_), &st) == 0 : ::stat(real_.c_str(), &st) == 0;
    if (has) {
        id.has_inode = true;
        id.dev = st.st_dev;
        id.ino = st.st_ino;
        struct stat null {};
        id.null_device = S_ISCHR(st.st_mode) && ::stat("/dev/null", &null) == 0 && st.st_rdev == null.st_rdev;
    }
    if (!temp_.empty()) {
        std::error_code ec;
        const std::filesystem::path p = std::filesystem::weakly_canonical(std::filesystem::absolute(real_), ec);
        id.path = ec ? real_ : p.string();
    }
    return id;
}

void write_file_atomically(const std::string& path, std::string_view data) {
    AtomicFile f(path);
    f.write(data);
    f.commit();
}

// ---- OutputSet -------------------------------------------------------------

namespace {

bool same_output(const AtomicFile::Identity& a, const AtomicFile::Identity& b) {
    if (a.has_inode && b.has_inode && a.dev == b.dev && a.ino == b.ino) {
        return !(a.null_device && b.null_device);
    }
    return !a.path.empty() && a.path == b.path;
}

}  // namespace

OutputSet::OutputSet(std::vector<NamedPath> outputs, const std::vector<NamedPath>& inputs)
    : names_(std::move(outputs)) {
    refuse_output_over_input(inputs, names_);
    std::vector<AtomicFile::Identity> ids;
    for (const NamedPath& n : names_) {
        files_.push_back(std::make_unique<AtomicFile>(n.path, n.option));
        ids.push_back(files_.back()->identity());
        for (std::size_t i = 0; i + 1 < ids.size(); ++i) {
            if (same_output(ids[i], ids.back())) {
                throw std::runtime_error(files_.back()->name() + " is also " + files_[i]->name() +
                                         ": the same file or stream; two outputs need two files (nothing was written)");
            }
        }
    }
}

AtomicFile& OutputSet::operator[](std::string_view option) {
    for (std::size_t i = 0; i < names_.size(); ++i) {
        if (names_[i].option == option) {
            return *files_[i];
        }
    }
    throw std::logic_error("no output " + std::string(option) + " was declared");
}

bool OutputSet::has(std::string_view option) const noexcept {
    for (const NamedPath& n : names_) {
        if (n.option == option) {
            return true;
        }
    }
    return false;
}

void OutputSet::commit() {
    for (const auto& f : files_) {  // every write complete before any rename
        f->complete();
    }
    const CommitWindow window;  // no cleanup signal acts between two renames
    for (std::size_t i = 0; i < files_.size(); ++i) {
        try {
            files_[i]->install();
        } catch (const std::runtime_error& e) {
            if (i == 0) {
                throw;  // nothing replaced: the temporary files go as usual
            }
            std::string replaced;
            std::string left;
            for (std::size_t k = 0; k < files_.size(); ++k) {
                if (k < i) {
                    replaced += (replaced.empty() ? "" : ", ") + files_[k]->name();
                } else if (!files_[k]->streamed()) {
                    files_[k]->keep_temporary();
                    left += (left.empty() ? "" : ", ") + files_[k]->name() + " (complete in " + files_[k]->temporary() +
                            ")";
                }
            }
            throw std::runtime_error(std::string(e.what()) + "; replaced already: " + replaced +
                                     "; left as they were: " + left +
                                     ": rename each temporary file over its output to complete the run's outputs");
        }
    }
}

// ---- same-file checks -----------------------------------------------------

void refuse_same_output(const NamedPath& first, const NamedPath& second) {
    namespace fs = std::filesystem;
    if (is_null_device(first.path) && is_null_device(second.path)) {
        return;  // nothing to splice: any number of outputs may go there
    }
    std::error_code ec;
    const fs::path a = fs::weakly_canonical(fs::absolute(first.path), ec);
    const fs::path b = fs::weakly_canonical(fs::absolute(second.path), ec);
    if (first.path == second.path || (!ec && a == b)) {
        throw std::runtime_error(second.option + " " + second.path + " is also " + first.option +
                                 ": the two files need two paths");
    }
}

namespace {

struct FileId {
    const NamedPath* named;
    dev_t dev;
    ino_t ino;
};

// The inputs that exist as files or streams ("-": standard input) other
// than character devices: a terminal or /dev/null holds nothing an output
// could destroy.
std::vector<FileId> input_ids(const std::vector<NamedPath>& inputs) {
    std::vector<FileId> in_ids;
    for (const NamedPath& p : inputs) {
        struct stat st {};
        const bool is_stdin = p.path == "-";
        if (!p.path.empty() && (is_stdin ? ::fstat(STDIN_FILENO, &st) : ::stat(p.path.c_str(), &st)) == 0 &&
            !S_ISCHR(st.st_mode)) {
            in_ids.push_back({&p, st.st_dev, st.st_ino});
        }
    }
    return in_ids;
}

// Refuses the output `out` (its stat st) when it is one of the inputs or an
// output already seen.
void refuse_clash(const NamedPath& out, const struct stat& st, const std::vector<FileId>& in_ids,
                  const std::vector<FileId>& out_ids) {
    for (const FileId& in : in_ids) {
        if (in.dev == st.st_dev && in.ino == st.st_ino) {
            throw std::runtime_error((out.path == "-" ? std::string("standard output") : out.option + " " + out.path) +
                                     " is the same file as the input " + in.named->option + " " + in.named->path +
                                     ": refusing to overwrite an input (nothing was read or written)");
        }
    }
    for (const FileId& o : out_ids) {
        if (o.dev == st.st_dev && o.ino == st.st_ino) {
            throw std::runtime_error((out.path == "-" ? std::string("standard output") : out.option + " " + out.path) +
                                     " is also " + o.named->option + " " + o.named->path +
                                     ": the same file or stream; two outputs need two files (nothing was written)");
        }
    }
}

}  // namespace

void refuse_output_over_input(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs,
                              bool check_stdout) {
    const std::vector<FileId> in_ids = input_ids(inputs);
    std::vector<FileId> out_ids;
    const NamedPath stdout_name{"standard output", "-"};
    for (const NamedPath& p : outputs) {
        struct stat st {};
        const bool is_stdout = p.path == "-";
        if (is_stdout ? ::fstat(STDOUT_FILENO, &st) != 0 : ::stat(p.path.c_str(), &st) != 0) {
            continue;  // does not exist yet: cannot be an input
        }
        refuse_clash(p, st, in_ids, out_ids);
        if (S_ISREG(st.st_mode)) {
            out_ids.push_back({&p, st.st_dev, st.st_ino});
        }
    }
    struct stat st {};
    if (check_stdout && ::fstat(STDOUT_FILENO, &st) == 0 && S_ISREG(st.st_mode)) {
        refuse_clash(stdout_name, st, in_ids, out_ids);
    }
}

// ---- signals -----------------------------------------------------------------

void install_signal_cleanup() {
    for (const int sig : kCleanupSignals) {
        struct sigaction old {};
        if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) {
            continue;  // ignored by whoever started us (nohup): keep it so
        }
        struct sigaction sa {};
        sa.sa_handler = on_cleanup_signal;
        ::sigemptyset(&sa.sa_mask);
        for (const int other : kCleanupSignals) {  // one cleanup at a time
            ::sigaddset(&sa.sa_mask, other);
        }
        ::sigaction(sig, &sa, nullptr);
    }
}

int cleanup_register_file(const std::string& path) {
    return claim(kFile, path, 0);
}
CleanupSignalsHeld::CleanupSignalsHeld() noexcept {
    sigset_t hold;
    sigemptyset(&hold);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
        sigaddset(&hold, sig);
    }
    pthread_sigmask(SIG_BLOCK, &hold, &previous_);
}

CleanupSignalsHeld::~CleanupSignalsHeld() {
    pthread_sigmask(SIG_SETMASK, &previous_, nullptr);  // a signal held meanwhile is handled now
}

int cleanup_register_folder(const std::string& path) {
    return claim(kFolder, path, 0);
}
int cleanup_register_child(pid_t pid) {
    return claim(kChild, std::string(), pid);
}
void cleanup_release(int slot) noexcept {
    if (slot >= 0 && static_cast<std::size_t>(slot) < kSlots) {
        g_slots[static_cast<std::size_t>(slot)].state.store(kFree, std::memory_order_release);
    }
}

}  // namespace ascorr::host
