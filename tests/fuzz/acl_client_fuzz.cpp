// AclClient over a scripted link: the controller's side of the conversation is the input, cut
// into the chunks one read returns at every '\0' byte; when they run out every read times out.
// The client sends a servo session's commands; whatever comes back, it must neither crash nor
// hang, and a reply it calls ok carries no error.
#include <cstdint>
#include <deque>
#include <string>

#include "robots/acl_client.h"
#include "robots/serial_port.h"

namespace {

class ScriptedLink : public oal::ByteLink {
 public:
  explicit ScriptedLink(const std::string& script) {
    std::size_t begin = 0;
    for (std::size_t end; (end = script.find('\0', begin)) != std::string::npos; begin = end + 1) {
      chunks_.push_back(script.substr(begin, end - begin));
    }
    chunks_.push_back(script.substr(begin));
  }
  oal::IoResult Write(const std::string& bytes, double) override {
    counters_.bytes_written += bytes.size();
    return {};
  }
  oal::IoResult ReadSome(std::string* out, double) override {
    if (chunks_.empty()) return {oal::IoStatus::kTimeout, "script ended"};
    *out += chunks_.front();
    counters_.bytes_read += chunks_.front().size();
    chunks_.pop_front();
    return {};
  }
  std::string DrainInput() override { return {}; }
  oal::LinkCounters counters() const override { return counters_; }

 private:
  std::deque<std::string> chunks_;
  oal::LinkCounters counters_;
};

void Expect(const oal::AclReply& reply) {
  if (reply.ok() && !reply.errors.empty()) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ScriptedLink link(std::string(reinterpret_cast<const char*>(data), size));
  oal::AclClientOptions options;
  options.reply_timeout_s = 0.05;
  oal::AclClient client(link, options);
  oal::AclPositionValues values;
  Expect(client.Ping());
  Expect(client.SetEcho(false));
  Expect(client.Command("SETPVC P1 X 1000"));
  Expect(client.Command("MOVE P1"));
  Expect(client.ListPosition("POSITION", &values));
  Expect(client.Abort());
  Expect(client.Command("HERE P1"));
  client.TakeAsyncText();
  return 0;
}
