#include "service/nats_client.hpp"

#include <nats/nats.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>

namespace skylane::service {

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

struct NatsClient::Impl {
  natsConnection* nc = nullptr;
  jsCtx* js = nullptr;
  std::map<std::string, kvStore*> buckets;
  std::atomic<int> async_failures{0};
  std::mutex error_mutex;
  std::string async_error;

  ~Impl() {
    for (auto& [name, kv] : buckets) kvStore_Destroy(kv);
    jsCtx_Destroy(js);
    natsConnection_Destroy(nc);
  }

  kvStore* bucket(const std::string& name) {
    if (const auto it = buckets.find(name); it != buckets.end()) return it->second;
    kvStore* kv = nullptr;
    check("key-value bucket " + name, js_KeyValue(&kv, js, name.c_str()));
    buckets[name] = kv;
    return kv;
  }

  static void onPublishError(jsCtx*, jsPubAckErr* pae, void* closure) {
    auto* self = static_cast<Impl*>(closure);
    self->async_failures.fetch_add(1);
    std::lock_guard lock(self->error_mutex);
    if (self->async_error.empty()) {
      self->async_error = std::string(natsStatus_GetText(pae->Err)) + (pae->ErrText != nullptr ? std::string(": ") + pae->ErrText : "");
    }
  }
};

NatsClient::NatsClient(const std::string& url, const std::string& name, std::chrono::milliseconds connect_timeout)
    : impl_(std::make_unique<Impl>()) {
  natsOptions* opts = nullptr;
  check("NATS options", natsOptions_Create(&opts));
  std::unique_ptr<natsOptions, void (*)(natsOptions*)> hold(opts, natsOptions_Destroy);
  check("NATS URL " + url, natsOptions_SetURL(opts, url.c_str()));
  natsOptions_SetName(opts, name.c_str());
  natsOptions_SetTimeout(opts, connect_timeout.count());
  natsOptions_SetMaxReconnect(opts, -1);
  natsOptions_SetReconnectWait(opts, 200);
  natsOptions_SetReconnectBufSize(opts, 64 << 20);
  check("connecting to " + url, natsConnection_Connect(&impl_->nc, opts));
  jsOptions jo;
  jsOptions_Init(&jo);
  jo.Wait = 5000;
  jo.PublishAsync.MaxPending = 8192;
  jo.PublishAsync.StallWait = 10000;  // a busy server slows a publisher down rather than failing it
  jo.PublishAsync.ErrHandler = &Impl::onPublishError;
  jo.PublishAsync.ErrHandlerClosure = impl_.get();
  check("JetStream context", natsConnection_JetStream(&impl_->js, impl_->nc, &jo));
}

NatsClient::~NatsClient() = default;

void NatsClient::ensureStream(const NatsStreamSpec& spec) {
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
  natsStatus s = js_AddStream(&si, impl_->js, &cfg, nullptr, &jerr);
  if (s != NATS_OK && jerr == kStreamNameInUse) s = js_UpdateStream(&si, impl_->js, &cfg, nullptr, &jerr);
  check("stream " + spec.name, s, jerr);
  jsStreamInfo_Destroy(si);
}

void NatsClient::ensureBucket(const NatsBucketSpec& spec) {
  kvConfig kc;
  kvConfig_Init(&kc);
  kc.Bucket = spec.name.c_str();
  kc.History = static_cast<std::uint8_t>(spec.history);
  kc.TTL = spec.ttl.count() * kNsPerS;
  kc.StorageType = js_FileStorage;
  kvStore* kv = nullptr;
  check("key-value bucket " + spec.name, js_CreateKeyValue(&kv, impl_->js, &kc));
  if (const auto it = impl_->buckets.find(spec.name); it != impl_->buckets.end()) kvStore_Destroy(it->second);
  impl_->buckets[spec.name] = kv;
}

std::uint64_t NatsClient::publish(const std::string& subject, const std::string& data, const std::string& msg_id) {
  jsPubOptions po;
  jsPubOptions_Init(&po);
  if (!msg_id.empty()) po.MsgId = msg_id.c_str();
  jsPubAck* pa = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("publish to " + subject, js_Publish(&pa, impl_->js, subject.c_str(), data.data(), static_cast<int>(data.size()), &po, &jerr), jerr);
  const std::uint64_t seq = pa->Sequence;
  jsPubAck_Destroy(pa);
  return seq;
}

void NatsClient::publishAsync(const std::string& subject, const std::string& data, const std::string& msg_id) {
  jsPubOptions po;
  jsPubOptions_Init(&po);
  if (!msg_id.empty()) po.MsgId = msg_id.c_str();
  check("publish to " + subject, js_PublishAsync(impl_->js, subject.c_str(), data.data(), static_cast<int>(data.size()), &po));
}

void NatsClient::publishesComplete(std::chrono::milliseconds max_wait) {
  jsPubOptions po;
  jsPubOptions_Init(&po);
  po.MaxWait = max_wait.count();
  const natsStatus s = js_PublishAsyncComplete(impl_->js, &po);
  if (s != NATS_OK) {
    // What is still in flight is given up: the caller starts again from its checkpoint.
    natsMsgList pending{};
    if (js_PublishAsyncGetPendingList(&pending, impl_->js) == NATS_OK) natsMsgList_Destroy(&pending);
    fail("waiting for publish acknowledgements", s);
  }
  if (impl_->async_failures.exchange(0) > 0) {
    std::lock_guard lock(impl_->error_mutex);
    const std::string why = impl_->async_error;
    impl_->async_error.clear();
    throw NatsError("a publish was refused: " + why);
  }
}

void NatsClient::publishCore(const std::string& subject, const std::string& data) {
  check("publish to " + subject, natsConnection_Publish(impl_->nc, subject.c_str(), data.data(), static_cast<int>(data.size())));
}

std::optional<NatsEntry> NatsClient::get(const std::string& bucket, const std::string& key) {
  kvEntry* e = nullptr;
  const natsStatus s = kvStore_Get(&e, impl_->bucket(bucket), key.c_str());
  if (s == NATS_NOT_FOUND) return std::nullopt;
  check("get " + bucket + "/" + key, s);
  const void* value = kvEntry_Value(e);  // null for an empty value
  NatsEntry out{value == nullptr ? std::string() : std::string(static_cast<const char*>(value), static_cast<std::size_t>(kvEntry_ValueLen(e))),
                kvEntry_Revision(e)};
  kvEntry_Destroy(e);
  return out;
}

std::vector<NatsEntry> NatsClient::history(const std::string& bucket, const std::string& key) {
  kvEntryList list{};
  const natsStatus s = kvStore_History(&list, impl_->bucket(bucket), key.c_str(), nullptr);
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

std::uint64_t NatsClient::put(const std::string& bucket, const std::string& key, const std::string& value) {
  std::uint64_t rev = 0;
  check("put " + bucket + "/" + key, kvStore_Put(&rev, impl_->bucket(bucket), key.c_str(), value.data(), static_cast<int>(value.size())));
  return rev;
}

void NatsClient::putAsync(const std::string& bucket, const std::string& key, const std::string& value) {
  publishAsync("$KV." + bucket + "." + key, value);
}

std::optional<std::uint64_t> NatsClient::create(const std::string& bucket, const std::string& key, const std::string& value) {
  std::uint64_t rev = 0;
  const natsStatus s = kvStore_Create(&rev, impl_->bucket(bucket), key.c_str(), value.data(), static_cast<int>(value.size()));
  if (s != NATS_OK && lostCompareAndSet(s, static_cast<jsErrCode>(0))) return std::nullopt;
  check("create " + bucket + "/" + key, s);
  return rev;
}

std::optional<std::uint64_t> NatsClient::update(const std::string& bucket, const std::string& key, const std::string& value,
                                                std::uint64_t revision) {
  std::uint64_t rev = 0;
  const natsStatus s = kvStore_Update(&rev, impl_->bucket(bucket), key.c_str(), value.data(), static_cast<int>(value.size()), revision);
  if (s != NATS_OK && lostCompareAndSet(s, static_cast<jsErrCode>(0))) return std::nullopt;
  check("update " + bucket + "/" + key, s);
  return rev;
}

void NatsClient::erase(const std::string& bucket, const std::string& key) {
  check("delete " + bucket + "/" + key, kvStore_Delete(impl_->bucket(bucket), key.c_str()));
}

std::vector<std::string> NatsClient::keys(const std::string& bucket) {
  kvKeysList list{};
  const natsStatus s = kvStore_Keys(&list, impl_->bucket(bucket), nullptr);
  if (s == NATS_NOT_FOUND) return {};
  check("keys of " + bucket, s);
  std::vector<std::string> out(list.Keys, list.Keys + list.Count);
  kvKeysList_Destroy(&list);
  return out;
}

struct NatsPull::Impl {
  natsSubscription* sub = nullptr;
  ~Impl() { natsSubscription_Destroy(sub); }
};

NatsPull::NatsPull(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
NatsPull::~NatsPull() = default;

namespace {

std::unique_ptr<NatsPull> bindPull(jsCtx* js, const std::string& stream, const std::string& durable, const std::string& filter) {
  jsSubOptions so;
  jsSubOptions_Init(&so);
  so.Stream = stream.c_str();
  so.Consumer = durable.c_str();
  auto impl = std::make_unique<NatsPull::Impl>();
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("pull subscription " + durable, js_PullSubscribe(&impl->sub, js, filter.c_str(), durable.c_str(), nullptr, &so, &jerr), jerr);
  return std::make_unique<NatsPull>(std::move(impl));
}

void addConsumer(jsCtx* js, const std::string& stream, jsConsumerConfig& cc) {
  jsConsumerInfo* ci = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check(std::string("consumer ") + cc.Durable + " on " + stream, js_AddConsumer(&ci, js, stream.c_str(), &cc, nullptr, &jerr), jerr);
  jsConsumerInfo_Destroy(ci);
}

}  // namespace

void NatsClient::deleteConsumer(const std::string& stream, const std::string& durable) {
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_DeleteConsumer(impl_->js, stream.c_str(), durable.c_str(), nullptr, &jerr);
  if (s != NATS_OK && s != NATS_NOT_FOUND && jerr != kConsumerNotFound) fail("deleting consumer " + durable, s, jerr);
}

std::unique_ptr<NatsPull> NatsClient::pullFrom(const std::string& stream, const std::string& durable, const std::string& filter,
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
  addConsumer(impl_->js, stream, cc);
  return bindPull(impl_->js, stream, durable, filter);
}

std::unique_ptr<NatsPull> NatsClient::pullShared(const std::string& stream, const std::string& durable, const std::string& filter,
                                                 std::chrono::seconds ack_wait) {
  jsConsumerConfig cc;
  jsConsumerConfig_Init(&cc);
  cc.Durable = durable.c_str();
  cc.DeliverPolicy = js_DeliverAll;
  cc.AckPolicy = js_AckExplicit;
  cc.AckWait = ack_wait.count() * kNsPerS;
  cc.FilterSubject = filter.c_str();
  addConsumer(impl_->js, stream, cc);
  return bindPull(impl_->js, stream, durable, filter);
}

std::uint64_t NatsClient::pending(const std::string& stream, const std::string& durable) {
  jsConsumerInfo* ci = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("consumer " + durable, js_GetConsumerInfo(&ci, impl_->js, stream.c_str(), durable.c_str(), nullptr, &jerr), jerr);
  const std::uint64_t n = ci->NumPending + static_cast<std::uint64_t>(ci->NumAckPending);
  jsConsumerInfo_Destroy(ci);
  return n;
}

std::uint64_t NatsClient::lastSequence(const std::string& stream) {
  jsStreamInfo* si = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  check("stream " + stream, js_GetStreamInfo(&si, impl_->js, stream.c_str(), nullptr, &jerr), jerr);
  const std::uint64_t last = si->State.LastSeq;
  jsStreamInfo_Destroy(si);
  return last;
}

std::optional<NatsMessage> NatsClient::message(const std::string& stream, std::uint64_t seq) {
  natsMsg* msg = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetMsg(&msg, impl_->js, stream.c_str(), seq, nullptr, &jerr);
  if (s == NATS_NOT_FOUND || jerr == static_cast<jsErrCode>(10037)) return std::nullopt;
  check("message " + std::to_string(seq) + " of " + stream, s, jerr);
  NatsMessage m = takeMessage(msg);
  m.stream_seq = seq;
  return m;
}

std::vector<NatsMessage> NatsPull::fetch(int batch, std::chrono::milliseconds wait) {
  natsMsgList list{};
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = natsSubscription_Fetch(&list, impl_->sub, batch, wait.count(), &jerr);
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

void NatsPull::ack(const NatsMessage& m) { check("ack", natsMsg_Ack(static_cast<natsMsg*>(m.handle.get()), nullptr)); }
void NatsPull::inProgress(const NatsMessage& m) { check("in progress", natsMsg_InProgress(static_cast<natsMsg*>(m.handle.get()), nullptr)); }
void NatsPull::nak(const NatsMessage& m) { check("nak", natsMsg_Nak(static_cast<natsMsg*>(m.handle.get()), nullptr)); }
void NatsPull::term(const NatsMessage& m) { check("term", natsMsg_Term(static_cast<natsMsg*>(m.handle.get()), nullptr)); }

}  // namespace skylane::service
