#pragma once
/// \file
/// \brief The interface between NatsClient (nats_client.cpp) and nats.c, internal to service/.
///
/// nats.c is not linked into skylane: with OpenSSL's libssl and protobuf-c behind it, it cost
/// every command about a millisecond at start (mapped, relocated, initialised), also those
/// that never talk to a NATS server (`integrity spp`, `--help`). The nats.c calls live in
/// libskylane_nats.so (service/nats_module.cpp), loaded with dlopen (maps/module_loader.hpp)
/// when the first NatsClient connects. NatsClient's calls forward to a NatsConnection.

#include "service/nats_client.hpp"

namespace skylane::service::detail {

/// \brief A pull subscription (NatsPull's fetch).
class NatsSubscription {
 public:
  virtual ~NatsSubscription() = default;
  [[nodiscard]] virtual std::vector<NatsMessage> fetch(int batch, std::chrono::milliseconds wait) = 0;
};

/// \brief One connection and its JetStream context (NatsClient's calls, one to one).
class NatsConnection {
 public:
  virtual ~NatsConnection() = default;
  virtual void ensureStream(const NatsStreamSpec& spec) = 0;
  virtual void ensureBucket(const NatsBucketSpec& spec) = 0;
  virtual std::uint64_t publish(const std::string& subject, const std::string& data, const std::string& msg_id) = 0;
  virtual void publishAsync(const std::string& subject, const std::string& data, const std::string& msg_id) = 0;
  virtual void publishesComplete(std::chrono::milliseconds max_wait) = 0;
  virtual void publishCore(const std::string& subject, const std::string& data) = 0;
  [[nodiscard]] virtual std::optional<NatsEntry> get(const std::string& bucket, const std::string& key) = 0;
  [[nodiscard]] virtual std::vector<NatsEntry> history(const std::string& bucket, const std::string& key) = 0;
  virtual std::uint64_t put(const std::string& bucket, const std::string& key, const std::string& value) = 0;
  [[nodiscard]] virtual std::optional<std::uint64_t> create(const std::string& bucket, const std::string& key,
                                                            const std::string& value) = 0;
  [[nodiscard]] virtual std::optional<std::uint64_t> update(const std::string& bucket, const std::string& key,
                                                            const std::string& value, std::uint64_t revision) = 0;
  virtual void erase(const std::string& bucket, const std::string& key) = 0;
  [[nodiscard]] virtual std::vector<std::string> keys(const std::string& bucket) = 0;
  [[nodiscard]] virtual std::unique_ptr<NatsSubscription> pullFrom(const std::string& stream, const std::string& durable,
                                                                   const std::string& filter, std::uint64_t start_seq,
                                                                   std::chrono::seconds inactive) = 0;
  virtual void deleteConsumer(const std::string& stream, const std::string& durable) = 0;
  [[nodiscard]] virtual std::unique_ptr<NatsSubscription> pullShared(const std::string& stream, const std::string& durable,
                                                                     const std::string& filter, std::chrono::seconds ack_wait) = 0;
  [[nodiscard]] virtual std::uint64_t pending(const std::string& stream, const std::string& durable) = 0;
  [[nodiscard]] virtual std::uint64_t lastSequence(const std::string& stream) = 0;
  [[nodiscard]] virtual std::optional<NatsMessage> message(const std::string& stream, std::uint64_t seq) = 0;
};

/// \brief What is said to the server of a message taken from a shared consumer.
enum class NatsSettle { kAck, kInProgress, kNak, kTerm };

/// \brief The entry points of the NATS module.
struct NatsModule {
  /// NatsClient's constructor: connects, or throws NatsError.
  std::unique_ptr<NatsConnection> (*connect)(const std::string& url, const std::string& name,
                                             std::chrono::milliseconds connect_timeout);
  /// NatsPull's ack, inProgress, nak and term; throws NatsError.
  void (*settle)(const NatsMessage& m, NatsSettle how);
};

/// \brief The interface version the module and skylane agree on (in the entry point's name).
inline constexpr int kNatsModuleAbi = 1;
/// \brief File name of the module.
inline constexpr const char* kNatsModuleFile = "libskylane_nats.so";

/// \brief The NATS module, loaded on the first call (thread-safe).
/// \throws std::runtime_error naming the places looked at when it is missing.
[[nodiscard]] const NatsModule& natsModule();

}  // namespace skylane::service::detail
