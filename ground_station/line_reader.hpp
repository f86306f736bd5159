#pragma once
// Reading the console's input one line at a time.
//
// On a terminal, lines are read through libedit: arrow keys, emacs-style
// editing and a history kept in ~/.ddswarm_history (when $HOME is writable).
// Otherwise (a pipe, a script, a test) plain lines are read from a stream,
// and the prompt and the line read are echoed so a transcript reads like an
// interactive session.
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace ddswarm::gs {

class LineReader {
 public:
  enum class Mode {
    kAuto,   ///< libedit when `in` is std::cin and stdin is a terminal, else plain
    kPlain,  ///< always plain lines from `in`
  };

  /// in: where plain lines come from; out: where plain mode writes prompts
  /// and echoes (libedit writes to the terminal itself).
  /// history_file: "" = ~/.ddswarm_history; only used with libedit.
  explicit LineReader(std::istream& in, std::ostream& out = std::cout, Mode mode = Mode::kAuto,
                      std::string history_file = "");
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Shows prompt and reads one line, without its line ending (\n or \r\n).
  /// Returns nullopt at end of input (Ctrl-D, closed pipe, end of stream) or
  /// once the interrupt predicate holds.
  std::optional<std::string> read(const std::string& prompt);

  /// stop() is polled while waiting for a key (every 0.2 s and after each
  /// signal), e.g. ddswarm::stop_requested, so one Ctrl-C ends read() even
  /// though libedit would otherwise restart the interrupted read.
  void set_interrupt(std::function<bool()> stop);

  /// True when the last nullopt from read() came from the interrupt predicate.
  bool interrupted() const { return interrupted_; }

  /// True when lines come through libedit (a terminal).
  bool interactive() const { return editline_ != nullptr; }

 private:
  struct Editline;
  bool stop_now();
  /// A line of standard input without the newline; false at its end or on a stop.
  bool read_stdin_line(std::string& s);

  std::istream& in_;
  std::ostream& out_;
  std::function<bool()> stop_;
  bool interrupted_ = false;
  std::unique_ptr<Editline> editline_;
};

}  // namespace ddswarm::gs
