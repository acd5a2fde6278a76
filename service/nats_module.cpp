/// \file
/// \brief libskylane_nats.so: NatsClient's calls on nats.c (nats_module.hpp), loaded with
/// dlopen when the first client connects.

#include "service/nats_module.hpp"

#include <nats/nats.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>

namespace skylane::service::detail {

namespace {

constexpr std::int64_t kNsPerS = 1000000000;
constexpr jsErrCode kStreamNameInUse = static_cast<jsErrCode>(10058);
constexpr jsErrCode kConsumerNotFound = static_cast<jsErrCode>(10014);
constexpr jsErrCode kWrongLastSequence = static_cast<jsErrCode>(10071);

/// The client's text for a failed call, with what was asked.
[[noreturn]] void fail(const std::string& what, natsStatus s, jsErrCode jerr = static_cast<jsErrCode>(0)) {
  const char* last = nats_GetLastError(nullptr);
  std::string text = what + ": " + natsStatus_GetText(s);
  if (last != nullptr && *last != '\0') text += std::string(" (") + last + ")";
  if (jerr != 0) text += " [JetStream error " + std::to_string(static_cast<int>(jerr)) + "]";
  throw NatsError(text);
}

void check(const std::string& what, natsStatus s, jsErrCode jerr = static_cast<jsErrCode>(0)) {
  if (s != NATS_OK) fail(what, s, jerr);
}

/// Whether the last failure was JetStream's "wrong last sequence" (a compare-and-set lost).
bool lostCompareAndSet(natsStatus s, jsErrCode jerr) {
  if (jerr == kWrongLastSequence) return true;
  const char* last = nats_GetLastError(nullptr);
  return s == NATS_ERR && last != nullptr && std::string(last).find("wrong last sequence") != std::string::npos;
}

NatsMessage takeMessage(natsMsg* msg) {
  NatsMessage m;
  const char* subject = natsMsg_GetSubject(msg);
  const char* data = natsMsg_GetData(msg);  // null for an empty message
  if (subject != nullptr) m.subject = subject;
  if (data != nullptr) m.data.assign(data, static_cast<std::size_t>(natsMsg_GetDataLength(msg)));
  jsMsgMetaData* meta = nullptr;
  if (natsMsg_GetMetaData(&meta, msg) == NATS_OK) {
    m.stream_seq = meta->Sequence.Stream;
    m.consumer_seq = meta->Sequence.Consumer;
    m.delivered = meta->NumDelivered;
    jsMsgMetaData_Destroy(meta);
  }
  m.handle = std::shared_ptr<void>(msg, [](void* p) { natsMsg_Destroy(static_cast<natsMsg*>(p)); });
  return m;
}

}  // namespace

/// A connection and its JetStream context, on nats.c.
class Connection final : public NatsConnection {
 public:
  Connection(const std::string& url, const std::string& name, std::chrono::milliseconds connect_timeout);
  ~Connection() override;
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  void ensureStream(const NatsStreamSpec& spec) override;
  void ensureBucket(const NatsBucketSpec& spec) override;
  std::uint64_t publish(const std::string& subject, const std::string& data, const std::string& msg_id) override;
  void publishAsync(const std::string& subject, const std::string& data, const std::string& msg_id) override;
  void publishesComplete(std::chrono::milliseconds max_wait) override;
  void publishCore(const std::string& subject, const std::string& data) override;
  std::optional<NatsEntry> get(const std::string& bucket, const std::string& key) override;
  std::vector<NatsEntry> history(const std::string& bucket, const std::string& key) override;
  std::uint64_t put(const std::string& bucket, const std::string& key, const std::string& value) override;
  std::optional<std::uint64_t> create(const std::string& bucket, const std::string& key, const std::string& value) override;
  std::optional<std::uint64_t> update(const std::string& bucket, const std::string& key, const std::string& value,
                                      std::uint64_t revision) override;
  void erase(const std::string& bucket, const std::string& key) override;
  std::vector<std::string> keys(const std::string& bucket) override;
  std::unique_ptr<NatsSubscription> pullFrom(const std::string& stream, const std::string& durable, const std::string& filter,
                                             std::uint64_t start_seq, std::chrono::seconds inactive) override;
  void deleteConsumer(const std::string& stream, const std::string& durable) override;
  std::unique_ptr<NatsSubscription> pullShared(const std::string& stream, const std::string& durable, const std::string& filter,
                                               std::chrono::seconds ack_wait) override;
  std::uint64_t pending(const std::string& stream, const std::string& durable) override;
  std::uint64_t lastSequence(const std::string& stream) override;
  std::optional<NatsMessage> message(const std::string& stream, std::uint64_t seq) override;

 private:
  kvStore* store(const std::string& name);  ///< the bucket, opened on first use
  static void onPublishError(jsCtx*, jsPubAckErr* pae, void* closure);

  natsConnection* nc_ = nullptr;
  jsCtx* js_ = nullptr;
  std::map<std::string, kvStore*> buckets_;
  std::atomic<int> async_failures_{0};
  std::mutex error_mutex_;
  std::string async_error_;
};

Connection::~Connection() {
  for (auto& [name, kv] : buckets_) kvStore_Destroy(kv);
  jsCtx_Destroy(js_);
  natsConnection_Destroy(nc_);
}

kvStore* Connection::store(const std::string& name) {
  if (const auto it = buckets_.find(name); it != buckets_.end()) return it->second;
  kvStore* kv = nullptr;
  check("key-value bucket " + name, js_KeyValue(&kv, js_, name.c_str()));
  buckets_[name] = kv;
  return kv;
}

void Connection::onPublishError(jsCtx*, jsPubAckErr* pae, void* closure) {
  auto* self = static_cast<Connection*>(closure);
  self->async_failures_.fetch_add(1);
  std::lock_guard lock(self->error_mutex_);
  if (self->async_error_.empty()) {
    self->async_error_ = std::string(natsStatus_GetText(pae->Err)) + (pae->ErrText != nullptr ? std::string(": ") + pae->ErrText : "");
  }
}

Connection::Connection(const std::string& url, const std::string& name, std::chrono::milliseconds connect_timeout) {
  natsOptions* opts = nullptr;
  check("NATS options", natsOptions_Create(&opts));
  std::unique_ptr<natsOptions, void (*)(natsOptions*)> hold(opts, natsOptions_Destroy);
  check("NATS URL " + url, natsOptions_SetURL(opts, url.c_str()));
  natsOptions_SetName(opts, name.c_str());
  natsOptions_SetTimeout(opts, connect_timeout.count());
  natsOptions_SetMaxReconnect(opts, -1);
  natsOptions_SetReconnectWait(opts, 200);
  natsOptions_SetReconnectBufSize(opts, 64 << 20);
  check("connecting to " + url, natsConnection_Connect(&nc_, opts));
  jsOptions jo;
  jsOptions_Init(&jo);
  jo.Wait = 5000;
  jo.PublishAsync.MaxPending = 8192;
  jo.PublishAsync.StallWait = 10000;  // a busy server slows a publisher down rather than failing it
  jo.PublishAsync.ErrHandler = &Connection::onPublishError;
  jo.PublishAsync.ErrHandlerClosure = this;
  try {
    check("JetStream context", natsConnection_JetStream(&js_, nc_, &jo));
  } catch (const NatsError&) {
    natsConnection_Destroy(nc_);  // the destructor does not run for a constructor that throws
    throw;
  }
}

void Connection::ensureStream(const NatsStreamSpec& spec) {
  std::vector<const char*> subjects;
  for (const auto& s : spec.subjects) subjects.push_back(s.c_str());
  jsStreamConfig cfg;
  jsStreamConfig_Init(&cfg);
  cfg.Name = spec.name.c_str();
  cfg.Subjects = subjects.data();
  cfg.SubjectsLen = static_cast<int>(subjects.size());
  cfg.Storage = js_FileStorage;
  cfg.Retention = spec.work_queue ? js_WorkQueuePolicy : js_LimitsPolicy;
  cfg.Duplicates = spec.duplicate_window.count() * kNsPerS;
  cfg.MaxAge = spec.max_age.count() * kNsPerS;
  cfg.MaxBytes = spec.max_bytes;
  jsStreamInfo* si = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  natsStatus s = js_AddStream(&si, js_, &cfg, nullptr, &jerr);
  if (s != NATS_OK && jerr == kStreamNameInUse) s = js_UpdateStream(&si, js_, &cfg, nullptr, &jerr);
  check("stream " + spec.name, s, jerr);
  jsStreamInfo_Destroy(si);
}

void Connection::ensureBucket(const NatsBucketSpec& spec) {
  kvConfig kc;
  kvConfig_Init(&kc);
  kc.Bucket = spec.name.c_str();
  kc.History = static_cast<std::uint8_t>(spec.history);
  kc.TTL = spec.ttl.count() * kNsPerS;
  kc.StorageType = js_FileStorage;
  kvStore* kv = nullptr;
  check("key-value bucket " + spec.name, js_CreateKeyValue(&kv, js_, &kc));
  if (const auto it = buckets_.find(spec.name); it != buckets_.end()) kvStore_Destroy(it->second);
  buckets_[spec.name] = kv;
}

std::uint64_t Connection::publish(const std::string& subject, const std::string& data, const std::string& msg_id) {
  jsPubOptions po;
  jsPubOptions_Init(&po);
  if (!msg_id.empty()) po.MsgId = msg_id.c_str();
  jsPubAck* pa = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("publish to " + subject, js_Publish(&pa, js_, subject.c_str(), data.data(), static_cast<int>(data.size()), &po, &jerr), jerr);
  const std::uint64_t seq = pa->Sequence;
  jsPubAck_Destroy(pa);
  return seq;
}

void Connection::publishAsync(const std::string& subject, const std::string& data, const std::string& msg_id) {
  jsPubOptions po;
  jsPubOptions_Init(&po);
  if (!msg_id.empty()) po.MsgId = msg_id.c_str();
  check("publish to " + subject, js_PublishAsync(js_, subject.c_str(), data.data(), static_cast<int>(data.size()), &po));
}

void Connection::publishesComplete(std::chrono::milliseconds max_wait) {
  jsPubOptions po;
  jsPubOptions_Init(&po);
  po.MaxWait = max_wait.count();
  const natsStatus s = js_PublishAsyncComplete(js_, &po);
  if (s != NATS_OK) {
    // What is still in flight is given up: the caller starts again from its checkpoint.
    natsMsgList pending{};
    if (js_PublishAsyncGetPendingList(&pending, js_) == NATS_OK) natsMsgList_Destroy(&pending);
    fail("waiting for publish acknowledgements", s);
  }
  if (async_failures_.exchange(0) > 0) {
    std::lock_guard lock(error_mutex_);
    const std::string why = async_error_;
    async_error_.clear();
    throw NatsError("a publish was refused: " + why);
  }
}

void Connection::publishCore(const std::string& subject, const std::string& data) {
  check("publish to " + subject, natsConnection_Publish(nc_, subject.c_str(), data.data(), static_cast<int>(data.size())));
}

std::optional<NatsEntry> Connection::get(const std::string& bucket, const std::string& key) {
  kvEntry* e = nullptr;
  const natsStatus s = kvStore_Get(&e, store(bucket), key.c_str());
  if (s == NATS_NOT_FOUND) return std::nullopt;
  check("get " + bucket + "/" + key, s);
  const void* value = kvEntry_Value(e);  // null for an empty value
  NatsEntry out{value == nullptr ? std::string() : std::string(static_cast<const char*>(value), static_cast<std::size_t>(kvEntry_ValueLen(e))),
                kvEntry_Revision(e)};
  kvEntry_Destroy(e);
  return out;
}

std::vector<NatsEntry> Connection::history(const std::string& bucket, const std::string& key) {
  kvEntryList list{};
  const natsStatus s = kvStore_History(&list, store(bucket), key.c_str(), nullptr);
  if (s == NATS_NOT_FOUND) return {};
  check("history of " + bucket + "/" + key, s);
  std::vector<NatsEntry> out;
  for (int i = 0; i < list.Count; ++i) {
    kvEntry* e = list.Entries[i];
    if (kvEntry_Operation(e) != kvOp_Put) continue;
    const void* value = kvEntry_Value(e);
    out.push_back({value == nullptr ? std::string() : std::string(static_cast<const char*>(value), static_cast<std::size_t>(kvEntry_ValueLen(e))),
                   kvEntry_Revision(e)});
  }
  kvEntryList_Destroy(&list);
  return out;
}

std::uint64_t Connection::put(const std::string& bucket, const std::string& key, const std::string& value) {
  std::uint64_t rev = 0;
  check("put " + bucket + "/" + key, kvStore_Put(&rev, store(bucket), key.c_str(), value.data(), static_cast<int>(value.size())));
  return rev;
}

std::optional<std::uint64_t> Connection::create(const std::string& bucket, const std::string& key, const std::string& value) {
  std::uint64_t rev = 0;
  const natsStatus s = kvStore_Create(&rev, store(bucket), key.c_str(), value.data(), static_cast<int>(value.size()));
  if (s != NATS_OK && lostCompareAndSet(s, static_cast<jsErrCode>(0))) return std::nullopt;
  check("create " + bucket + "/" + key, s);
  return rev;
}

std::optional<std::uint64_t> Connection::update(const std::string& bucket, const std::string& key, const std::string& value,
                                                std::uint64_t revision) {
  std::uint64_t rev = 0;
  const natsStatus s = kvStore_Update(&rev, store(bucket), key.c_str(), value.data(), static_cast<int>(value.size()), revision);
  if (s != NATS_OK && lostCompareAndSet(s, static_cast<jsErrCode>(0))) return std::nullopt;
  check("update " + bucket + "/" + key, s);
  return rev;
}

void Connection::erase(const std::string& bucket, const std::string& key) {
  check("delete " + bucket + "/" + key, kvStore_Delete(store(bucket), key.c_str()));
}

std::vector<std::string> Connection::keys(const std::string& bucket) {
  kvKeysList list{};
  const natsStatus s = kvStore_Keys(&list, store(bucket), nullptr);
  if (s == NATS_NOT_FOUND) return {};
  check("keys of " + bucket, s);
  std::vector<std::string> out(list.Keys, list.Keys + list.Count);
  kvKeysList_Destroy(&list);
  return out;
}

namespace {

/// A pull subscription on nats.c.
class Subscription final : public NatsSubscription {
 public:
  Subscription() = default;
  ~Subscription() override { natsSubscription_Destroy(sub); }
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;
  std::vector<NatsMessage> fetch(int batch, std::chrono::milliseconds wait) override;

  natsSubscription* sub = nullptr;
};

std::unique_ptr<NatsSubscription> bindPull(jsCtx* js, const std::string& stream, const std::string& durable, const std::string& filter) {
  jsSubOptions so;
  jsSubOptions_Init(&so);
  so.Stream = stream.c_str();
  so.Consumer = durable.c_str();
  auto pull = std::make_unique<Subscription>();
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("pull subscription " + durable, js_PullSubscribe(&pull->sub, js, filter.c_str(), durable.c_str(), nullptr, &so, &jerr), jerr);
  return pull;
}

void addConsumer(jsCtx* js, const std::string& stream, jsConsumerConfig& cc) {
  jsConsumerInfo* ci = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check(std::string("consumer ") + cc.Durable + " on " + stream, js_AddConsumer(&ci, js, stream.c_str(), &cc, nullptr, &jerr), jerr);
  jsConsumerInfo_Destroy(ci);
}

}  // namespace

void Connection::deleteConsumer(const std::string& stream, const std::string& durable) {
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_DeleteConsumer(js_, stream.c_str(), durable.c_str(), nullptr, &jerr);
  if (s != NATS_OK && s != NATS_NOT_FOUND && jerr != kConsumerNotFound) fail("deleting consumer " + durable, s, jerr);
}

std::unique_ptr<NatsSubscription> Connection::pullFrom(const std::string& stream, const std::string& durable, const std::string& filter,
                                               std::uint64_t start_seq, std::chrono::seconds inactive) {
  deleteConsumer(stream, durable);
  jsConsumerConfig cc;
  jsConsumerConfig_Init(&cc);
  cc.Durable = durable.c_str();
  cc.DeliverPolicy = js_DeliverByStartSequence;
  cc.OptStartSeq = std::max<std::uint64_t>(start_seq, 1);
  cc.AckPolicy = js_AckNone;
  cc.FilterSubject = filter.c_str();
  cc.InactiveThreshold = inactive.count() * kNsPerS;
  addConsumer(js_, stream, cc);
  return bindPull(js_, stream, durable, filter);
}

std::unique_ptr<NatsSubscription> Connection::pullShared(const std::string& stream, const std::string& durable, const std::string& filter,
                                                 std::chrono::seconds ack_wait) {
  jsConsumerConfig cc;
  jsConsumerConfig_Init(&cc);
  cc.Durable = durable.c_str();
  cc.DeliverPolicy = js_DeliverAll;
  cc.AckPolicy = js_AckExplicit;
  cc.AckWait = ack_wait.count() * kNsPerS;
  cc.FilterSubject = filter.c_str();
  addConsumer(js_, stream, cc);
  return bindPull(js_, stream, durable, filter);
}

std::uint64_t Connection::pending(const std::string& stream, const std::string& durable) {
  jsConsumerInfo* ci = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("consumer " + durable, js_GetConsumerInfo(&ci, js_, stream.c_str(), durable.c_str(), nullptr, &jerr), jerr);
  const std::uint64_t n = ci->NumPending + static_cast<std::uint64_t>(ci->NumAckPending);
  jsConsumerInfo_Destroy(ci);
  return n;
}

std::uint64_t Connection::lastSequence(const std::string& stream) {
  jsStreamInfo* si = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("stream " + stream, js_GetStreamInfo(&si, js_, stream.c_str(), nullptr, &jerr), jerr);
  const std::uint64_t last = si->State.LastSeq;
  jsStreamInfo_Destroy(si);
  return last;
}

std::optional<NatsMessage> Connection::message(const std::string& stream, std::uint64_t seq) {
  natsMsg* msg = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetMsg(&msg, js_, stream.c_str(), seq, nullptr, &jerr);
  if (s == NATS_NOT_FOUND || jerr == static_cast<jsErrCode>(10037)) return std::nullopt;
  check("message " + std::to_string(seq) + " of " + stream, s, jerr);
  NatsMessage m = takeMessage(msg);
  m.stream_seq = seq;
  return m;
}

std::vector<NatsMessage> Subscription::fetch(int batch, std::chrono::milliseconds wait) {
  natsMsgList list{};
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = natsSubscription_Fetch(&list, sub, batch, wait.count(), &jerr);
  if (s == NATS_TIMEOUT) return {};
  check("fetch", s, jerr);
  std::vector<NatsMessage> out;
  out.reserve(static_cast<std::size_t>(list.Count));
  for (int i = 0; i < list.Count; ++i) {
    out.push_back(takeMessage(list.Msgs[i]));
    list.Msgs[i] = nullptr;
  }
  natsMsgList_Destroy(&list);
  return out;
}

namespace {

void settle(const NatsMessage& m, NatsSettle how) {
  auto* msg = static_cast<natsMsg*>(m.handle.get());
  switch (how) {
    case NatsSettle::kAck: check("ack", natsMsg_Ack(msg, nullptr)); return;
    case NatsSettle::kInProgress: check("in progress", natsMsg_InProgress(msg, nullptr)); return;
    case NatsSettle::kNak: check("nak", natsMsg_Nak(msg, nullptr)); return;
    case NatsSettle::kTerm: check("term", natsMsg_Term(msg, nullptr)); return;
  }
}

std::unique_ptr<NatsConnection> connect(const std::string& url, const std::string& name, std::chrono::milliseconds connect_timeout) {
  return std::make_unique<Connection>(url, name, connect_timeout);
}

}  // namespace
}  // namespace skylane::service::detail

/// The module's one exported symbol (its name carries kNatsModuleAbi).
extern "C" __attribute__((visibility("default"))) const skylane::service::detail::NatsModule* skylane_nats_module_v1() {
  static const skylane::service::detail::NatsModule module{&skylane::service::detail::connect, &skylane::service::detail::settle};
  return &module;
}
