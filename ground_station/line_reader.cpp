#include "ground_station/line_reader.hpp"

#include <histedit.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cwchar>

namespace ddswarm::gs {
namespace {

std::string default_history_file() {
  const char* home = std::getenv("HOME");
  if (!home || !*home) return "";
  return std::string(home) + "/.ddswarm_history";
}

void strip_line_ending(std::string& s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
}

// One byte of standard input, waiting with poll() so that stop() (a Ctrl-C,
// taken on the signal thread: common/process.hpp) ends the wait within
// 200 ms. Returns 1 (a byte), 0 (end of input or stop) or -1 (error).
int read_stdin_byte(const std::function<bool()>& stop, char& byte) {
  for (;;) {
    if (stop && stop()) return 0;
    pollfd p{STDIN_FILENO, POLLIN, 0};
    const int ready = ::poll(&p, 1, 200);
    if (ready < 0 && errno != EINTR) return -1;
    if (ready <= 0) continue;
    const ssize_t n = ::read(STDIN_FILENO, &byte, 1);
    if (n == 0) return 0;
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return -1;
    }
    return 1;
  }
}

}  // namespace

// Owns the libedit state; el_end/history_end run in the destructor.
struct LineReader::Editline {
  EditLine* el = nullptr;
  History* hist = nullptr;
  HistEvent ev{};
  std::string prompt;
  std::string history_file;
  std::function<bool()> stop;  ///< copied from the LineReader before each read

  static Editline* self(EditLine* el) {
    void* p = nullptr;
    el_get(el, EL_CLIENTDATA, &p);
    return static_cast<Editline*>(p);
  }

  static char* prompt_fn(EditLine* el) { return self(el)->prompt.data(); }

  // libedit's own reader retries a read interrupted by a signal, so a SIGINT
  // handler that only sets a flag would not end the prompt. This one waits
  // with poll() and checks the flag. Returns 1 (a character), 0 (end) or -1.
  static int getc_fn(EditLine* el, wchar_t* out) {
    Editline* e = self(el);
    std::mbstate_t state{};
    for (;;) {
      char byte = 0;
      const int got = read_stdin_byte(e->stop, byte);
      if (got <= 0) return got;
      wchar_t wc = 0;
      const std::size_t used = std::mbrtowc(&wc, &byte, 1, &state);
      if (used == static_cast<std::size_t>(-2)) continue;  // more bytes of this character
      if (used == static_cast<std::size_t>(-1)) wc = static_cast<unsigned char>(byte);
      *out = wc;
      return 1;
    }
  }

  explicit Editline(std::string file) : history_file(std::move(file)) {
    hist = history_init();
    el = el_init("ddswarm", stdin, stdout, stderr);
    if (!hist || !el) return;
    history(hist, &ev, H_SETSIZE, 1000);
    history(hist, &ev, H_SETUNIQUE, 1);
    // A missing or unreadable history file just means an empty history.
    if (!history_file.empty()) history(hist, &ev, H_LOAD, history_file.c_str());
    el_set(el, EL_CLIENTDATA, this);
    el_set(el, EL_PROMPT, &Editline::prompt_fn);
    el_set(el, EL_EDITOR, "emacs");
    el_set(el, EL_SIGNAL, 1);  // restore the terminal on signals, track resizes
    el_set(el, EL_GETCFN, &Editline::getc_fn);
    el_set(el, EL_HIST, history, hist);
    el_source(el, nullptr);  // the user's ~/.editrc, if any
  }

  ~Editline() {
    if (el) el_end(el);
    if (hist) history_end(hist);
  }

  bool ok() const { return el && hist; }

  std::optional<std::string> read(const std::string& p) {
    prompt = p;
    int count = 0;
    const char* line = el_gets(el, &count);
    if (!line || count <= 0) {
      std::fputc('\n', stdout);  // leave the cursor on a fresh line after Ctrl-D
      std::fflush(stdout);
      return std::nullopt;
    }
    std::string s(line, static_cast<std::size_t>(count));
    strip_line_ending(s);
    if (s.find_first_not_of(" \t") != std::string::npos) {
      history(hist, &ev, H_ENTER, s.c_str());
      // Saved after every line so a killed session keeps its history; a
      // read-only home directory is not an error.
      if (!history_file.empty()) history(hist, &ev, H_SAVE, history_file.c_str());
    }
    return s;
  }
};

LineReader::LineReader(std::istream& in, std::ostream& out, Mode mode, std::string history_file)
    : in_(in), out_(out) {
  if (mode == Mode::kAuto && &in == &std::cin && ::isatty(STDIN_FILENO) &&
      ::isatty(STDOUT_FILENO)) {
    auto e = std::make_unique<Editline>(history_file.empty() ? default_history_file()
                                                             : std::move(history_file));
    if (e->ok()) editline_ = std::move(e);
  }
}

LineReader::~LineReader() = default;

void LineReader::set_interrupt(std::function<bool()> stop) { stop_ = std::move(stop); }

bool LineReader::read_stdin_line(std::string& s) {
  // Byte by byte from the descriptor, not through std::cin's buffer: the
  // wait must see a stop, and no line may sit in a buffer poll() cannot see.
  s.clear();
  char byte = 0;
  int got = 0;
  while ((got = read_stdin_byte(stop_, byte)) == 1 && byte != '\n') s.push_back(byte);
  return got == 1 || (got == 0 && !s.empty() && !(stop_ && stop_()));
}

bool LineReader::stop_now() {
  interrupted_ = stop_ && stop_();
  return interrupted_;
}

std::optional<std::string> LineReader::read(const std::string& prompt) {
  if (stop_now()) return std::nullopt;
  std::optional<std::string> line;
  if (editline_) {
    out_.flush();
    editline_->stop = stop_;
    line = editline_->read(prompt);
  } else {
    out_ << prompt << std::flush;
    std::string s;
    if (&in_ == &std::cin ? read_stdin_line(s) : static_cast<bool>(std::getline(in_, s))) {
      strip_line_ending(s);
      out_ << s << '\n';
      line = std::move(s);
    } else {
      out_ << '\n';
    }
  }
  if (!line) stop_now();
  return line;
}

}  // namespace ddswarm::gs
