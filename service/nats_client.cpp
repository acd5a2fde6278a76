/// \file
/// \brief NatsClient and NatsPull: their calls forwarded to the NATS module (nats_module.hpp).

#include "service/nats_client.hpp"

#include "maps/module_loader.hpp"
#include "service/nats_module.hpp"

namespace skylane::service {

namespace detail {

const NatsModule& natsModule() {
  static const NatsModule& module = []() -> const NatsModule& {
    const maps::detail::ModuleSpec spec{kNatsModuleFile, "SKYLANE_NATS_MODULE", "skylane_nats_module_v1",
                                        SKYLANE_NATS_MODULE_BUILD_PATH, SKYLANE_NATS_MODULE_INSTALL_PATH,
                                        "talking to a NATS server"};
    static_assert(kNatsModuleAbi == 1, "rename the entry point with the ABI version");
    return maps::detail::moduleTable<NatsModule>(spec);
  }();
  return module;
}

}  // namespace detail

NatsClient::NatsClient(const std::string& url, const std::string& name, std::chrono::milliseconds connect_timeout)
    : impl_(detail::natsModule().connect(url, name, connect_timeout)) {}

NatsClient::~NatsClient() = default;

void NatsClient::ensureStream(const NatsStreamSpec& spec) { impl_->ensureStream(spec); }
void NatsClient::ensureBucket(const NatsBucketSpec& spec) { impl_->ensureBucket(spec); }

std::uint64_t NatsClient::publish(const std::string& subject, const std::string& data, const std::string& msg_id) {
  return impl_->publish(subject, data, msg_id);
}

void NatsClient::publishAsync(const std::string& subject, const std::string& data, const std::string& msg_id) {
  impl_->publishAsync(subject, data, msg_id);
}

void NatsClient::publishesComplete(std::chrono::milliseconds max_wait) { impl_->publishesComplete(max_wait); }
void NatsClient::publishCore(const std::string& subject, const std::string& data) { impl_->publishCore(subject, data); }

std::optional<NatsEntry> NatsClient::get(const std::string& bucket, const std::string& key) { return impl_->get(bucket, key); }

std::vector<NatsEntry> NatsClient::history(const std::string& bucket, const std::string& key) { return impl_->history(bucket, key); }

std::uint64_t NatsClient::put(const std::string& bucket, const std::string& key, const std::string& value) {
  return impl_->put(bucket, key, value);
}

void NatsClient::putAsync(const std::string& bucket, const std::string& key, const std::string& value) {
  impl_->publishAsync("$KV." + bucket + "." + key, value, {});
}

std::optional<std::uint64_t> NatsClient::create(const std::string& bucket, const std::string& key, const std::string& value) {
  return impl_->create(bucket, key, value);
}

std::optional<std::uint64_t> NatsClient::update(const std::string& bucket, const std::string& key, const std::string& value,
                                                std::uint64_t revision) {
  return impl_->update(bucket, key, value, revision);
}

void NatsClient::erase(const std::string& bucket, const std::string& key) { impl_->erase(bucket, key); }
std::vector<std::string> NatsClient::keys(const std::string& bucket) { return impl_->keys(bucket); }

std::unique_ptr<NatsPull> NatsClient::pullFrom(const std::string& stream, const std::string& durable, const std::string& filter,
                                               std::uint64_t start_seq, std::chrono::seconds inactive) {
  return std::make_unique<NatsPull>(impl_->pullFrom(stream, durable, filter, start_seq, inactive));
}

void NatsClient::deleteConsumer(const std::string& stream, const std::string& durable) { impl_->deleteConsumer(stream, durable); }

std::unique_ptr<NatsPull> NatsClient::pullShared(const std::string& stream, const std::string& durable, const std::string& filter,
                                                 std::chrono::seconds ack_wait) {
  return std::make_unique<NatsPull>(impl_->pullShared(stream, durable, filter, ack_wait));
}

std::uint64_t NatsClient::pending(const std::string& stream, const std::string& durable) { return impl_->pending(stream, durable); }
std::uint64_t NatsClient::lastSequence(const std::string& stream) { return impl_->lastSequence(stream); }

std::optional<NatsMessage> NatsClient::message(const std::string& stream, std::uint64_t seq) { return impl_->message(stream, seq); }

NatsPull::NatsPull(std::unique_ptr<detail::NatsSubscription> impl) : impl_(std::move(impl)) {}
NatsPull::~NatsPull() = default;

std::vector<NatsMessage> NatsPull::fetch(int batch, std::chrono::milliseconds wait) { return impl_->fetch(batch, wait); }

void NatsPull::ack(const NatsMessage& m) { detail::natsModule().settle(m, detail::NatsSettle::kAck); }
void NatsPull::inProgress(const NatsMessage& m) { detail::natsModule().settle(m, detail::NatsSettle::kInProgress); }
void NatsPull::nak(const NatsMessage& m) { detail::natsModule().settle(m, detail::NatsSettle::kNak); }
void NatsPull::term(const NatsMessage& m) { detail::natsModule().settle(m, detail::NatsSettle::kTerm); }

}  // namespace skylane::service
