#pragma once
/// \file
/// \brief A small C++ face on the NATS C client (nats.c) for the JetStream workers: a
/// connection that reconnects, streams and key-value buckets made or checked at start,
/// publishing with a message id (JetStream drops a repeat of an id within the stream's
/// duplicate window), pull consumers that start at a stream sequence, and key-value puts and
/// compare-and-set updates. nats.c's types stay inside the NATS module (nats_module.hpp), loaded
/// when the first client connects.
///
/// Every call that talks to the server throws NatsError when it fails (server gone, timeout,
/// refused); a worker's loop catches it, waits, and starts its partition again from the last
/// checkpoint (track_worker.hpp). The first connection loads the module; when it is missing
/// that throws std::runtime_error naming the places looked at. NatsError is thrown inside the
/// module and caught here by type: libstdc++ matches exception types by name across shared
/// objects (a test connects to a refused port to keep that true).

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace skylane::service {

/// \brief A failed NATS or JetStream call: what was asked and the server's or client's answer.
class NatsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief A stream to make (or check) at start.
struct NatsStreamSpec {
  std::string name;
  std::vector<std::string> subjects;
  bool work_queue = false;                          ///< each message taken once, then removed
  std::chrono::seconds duplicate_window{600};       ///< ids remembered this long
  std::chrono::seconds max_age{0};                  ///< 0: kept until the limits below
  std::int64_t max_bytes = -1;
};

/// \brief A key-value bucket to make (or check) at start.
struct NatsBucketSpec {
  std::string name;
  int history = 1;                       ///< values kept per key (versions)
  std::chrono::seconds ttl{0};           ///< 0: keys live until deleted
};

/// \brief A message taken from a pull consumer.
struct NatsMessage {
  std::string subject;
  std::string data;
  std::uint64_t stream_seq = 0;
  std::uint64_t consumer_seq = 0;  ///< the consumer's delivery count (1, 2, … without acknowledgements)
  std::uint64_t delivered = 0;     ///< 1 at the first delivery
  std::shared_ptr<void> handle;  ///< the client's message (for ack)
};

/// \brief A key-value entry.
struct NatsEntry {
  std::string value;
  std::uint64_t revision = 0;
};

class NatsPull;
namespace detail {
class NatsConnection;
class NatsSubscription;
}  // namespace detail

/// \brief One connection and its JetStream context.
class NatsClient {
 public:
  /// \brief Connects to `url` (nats://host:port, several comma-separated); reconnects for ever
  /// after a loss. `name` shows in the server's connection list.
  /// \throws NatsError when no server answers within `connect_timeout`.
  NatsClient(const std::string& url, const std::string& name, std::chrono::milliseconds connect_timeout = std::chrono::seconds(5));
  ~NatsClient();
  NatsClient(const NatsClient&) = delete;
  NatsClient& operator=(const NatsClient&) = delete;

  /// \brief Makes the stream, or updates it to `spec` when it exists with other limits.
  void ensureStream(const NatsStreamSpec& spec);
  /// \brief Makes the bucket (or takes the existing one).
  void ensureBucket(const NatsBucketSpec& spec);

  /// \brief Publishes and waits for the stream's acknowledgement; `msg_id` (may be empty) makes a
  /// repeat within the duplicate window a no-op. Returns the stream sequence (of the first copy
  /// for a repeat).
  std::uint64_t publish(const std::string& subject, const std::string& data, const std::string& msg_id = {});
  /// \brief Publishes without waiting; publishesComplete() waits for every acknowledgement and
  /// throws NatsError if any publish since the last call failed.
  void publishAsync(const std::string& subject, const std::string& data, const std::string& msg_id = {});
  void publishesComplete(std::chrono::milliseconds max_wait = std::chrono::seconds(10));
  /// \brief A plain (core NATS) publish: no stream, no acknowledgement.
  void publishCore(const std::string& subject, const std::string& data);

  /// \brief A bucket's entry; none when the key is absent or deleted.
  [[nodiscard]] std::optional<NatsEntry> get(const std::string& bucket, const std::string& key);
  /// \brief Every value a bucket keeps for a key (its history), oldest first; deletions left out.
  [[nodiscard]] std::vector<NatsEntry> history(const std::string& bucket, const std::string& key);
  /// \brief Puts a value; returns its revision.
  std::uint64_t put(const std::string& bucket, const std::string& key, const std::string& value);
  /// \brief Puts a value without waiting (a publish to the bucket's subject; completed by
  /// publishesComplete()).
  void putAsync(const std::string& bucket, const std::string& key, const std::string& value);
  /// \brief Creates the key only if it is absent; its revision, or none when it exists.
  [[nodiscard]] std::optional<std::uint64_t> create(const std::string& bucket, const std::string& key, const std::string& value);
  /// \brief Updates the key only if its revision is still `revision`; the new one, or none.
  [[nodiscard]] std::optional<std::uint64_t> update(const std::string& bucket, const std::string& key, const std::string& value,
                                                    std::uint64_t revision);
  /// \brief Deletes a key (a no-op when absent).
  void erase(const std::string& bucket, const std::string& key);
  /// \brief The keys of a bucket (empty when it has none).
  [[nodiscard]] std::vector<std::string> keys(const std::string& bucket);

  /// \brief A durable pull consumer on `stream` for `filter`, made anew so that its first
  /// message is the one at `start_seq` (1: the stream's first). An existing consumer of that name
  /// is deleted first: its deliveries pending are forgotten, the caller's checkpoint says where
  /// to go on from. No acknowledgements: the caller's checkpoint is the consumer's position.
  /// `inactive` > 0: the server deletes the consumer after that long with no one fetching (a
  /// reader that died leaves nothing behind).
  [[nodiscard]] std::unique_ptr<NatsPull> pullFrom(const std::string& stream, const std::string& durable, const std::string& filter,
                                                   std::uint64_t start_seq, std::chrono::seconds inactive = std::chrono::seconds(0));
  /// \brief Deletes a consumer (a no-op when absent).
  void deleteConsumer(const std::string& stream, const std::string& durable);
  /// \brief A durable pull consumer shared by every worker that names it (a work queue):
  /// made when absent, joined when present.
  [[nodiscard]] std::unique_ptr<NatsPull> pullShared(const std::string& stream, const std::string& durable, const std::string& filter,
                                                     std::chrono::seconds ack_wait);
  /// \brief Messages of a consumer not yet delivered (the consumer's lag).
  [[nodiscard]] std::uint64_t pending(const std::string& stream, const std::string& durable);
  /// \brief The last sequence of a stream (0 when empty).
  [[nodiscard]] std::uint64_t lastSequence(const std::string& stream);
  /// \brief The stream's message at a sequence; none when absent.
  [[nodiscard]] std::optional<NatsMessage> message(const std::string& stream, std::uint64_t seq);

 private:
  std::unique_ptr<detail::NatsConnection> impl_;
};

/// \brief A pull subscription.
class NatsPull {
 public:
  ~NatsPull();
  NatsPull(const NatsPull&) = delete;
  NatsPull& operator=(const NatsPull&) = delete;
  /// \brief Up to `batch` messages, waiting at most `wait` for the first; empty on a quiet stream.
  [[nodiscard]] std::vector<NatsMessage> fetch(int batch, std::chrono::milliseconds wait);
  /// \brief Acknowledges a message (done: not delivered again).
  static void ack(const NatsMessage& m);
  /// \brief Tells the server the message is still being worked on (its ack wait starts again).
  static void inProgress(const NatsMessage& m);
  /// \brief Gives the message back for redelivery.
  static void nak(const NatsMessage& m);
  /// \brief Ends the message for good (a request that can never succeed).
  static void term(const NatsMessage& m);

  explicit NatsPull(std::unique_ptr<detail::NatsSubscription> impl);

 private:
  std::unique_ptr<detail::NatsSubscription> impl_;
};

}  // namespace skylane::service
