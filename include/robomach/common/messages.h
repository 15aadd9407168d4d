#pragma once
// What a workflow of the library has to say while it works (issue #36: one
// way for every workflow): notes and warnings as they happen, which a tool
// prints on stderr under its name and Python collects. A warning that
// flags the result is also in the result's findings (run_status.h); the
// sink only tells it as it is found.
#include <functional>
#include <string>

namespace robomach {

struct Message {
  enum class Kind {
    kInfo,     // what is being done and with what (a noise model, a fit), for the log
    kNote,     // a choice made for the user that they may want to know
    kWarning,  // something doubtful about the input or the result
  };
  Kind kind{Kind::kInfo};
  std::string text;
};
using MessageSink = std::function<void(const Message&)>;

/// Tells `text` to `sink`, if there is one: the one way a workflow speaks.
inline void Tell(const MessageSink& sink, Message::Kind kind, const std::string& text) {
  if (sink) sink({kind, text});
}

}  // namespace robomach
