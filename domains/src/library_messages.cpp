#include "ontime/domains/library_messages.hpp"

#include <igraph/igraph_error.h>
#include <ompl/util/Console.h>

#include <memory>
#include <mutex>
#include <string>
#include <utility>

namespace ontime::domains {
namespace {

std::mutex sink_mutex;
std::shared_ptr<const LibraryMessageSink> current_sink;

void deliver(std::string_view library, LibraryMessageLevel level, std::string_view text) {
  std::shared_ptr<const LibraryMessageSink> sink;
  {
    const std::lock_guard lock(sink_mutex);
    sink = current_sink;
  }
  if (sink && *sink) (*sink)(library, level, text);
}

class OmplToOnTime final : public ompl::msg::OutputHandler {
 public:
  void log(const std::string& text, ompl::msg::LogLevel level, const char* /*filename*/, int /*line*/) override {
    if (level < ompl::msg::LOG_WARN || level == ompl::msg::LOG_NONE) return;
    deliver("OMPL", level == ompl::msg::LOG_ERROR ? LibraryMessageLevel::error : LibraryMessageLevel::warning, text);
  }
};

extern "C" void igraph_to_ontime(const char* reason, const char* /*file*/, int /*line*/) {
  deliver("igraph", LibraryMessageLevel::warning, reason != nullptr ? reason : "");
}

}  // namespace

void set_library_message_sink(LibraryMessageSink sink) {
  auto shared = std::make_shared<const LibraryMessageSink>(std::move(sink));
  const std::lock_guard lock(sink_mutex);
  current_sink = std::move(shared);
}

namespace detail {

void route_ompl_messages() {
  static std::once_flag routed;
  std::call_once(routed, [] {
    static OmplToOnTime handler;  // OMPL keeps a pointer: alive for the whole process
    ompl::msg::useOutputHandler(&handler);
    ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  });
}

void route_igraph_messages() { igraph_set_warning_handler(igraph_to_ontime); }

}  // namespace detail
}  // namespace ontime::domains
