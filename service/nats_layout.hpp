#pragma once
/// \file
/// \brief skylane's subjects, streams and buckets on NATS JetStream (docs/nats.md).
///
/// - Fixes: published to `skylane.fix.<operator>.<flight>`; the server's subject mapping puts
///   them on `skylane.fixp.<partition>.<operator>.<flight>` (the partition a hash of operator and
///   flight, so one flight's fixes stay in order on one partition). Stream SKYLANE_FIXES.
/// - Events: `skylane.event.<operator>.<flight>` (an approval's on `skylane.event.<operator>.<id>`);
///   bad messages whose subject names no operator and flight on `skylane.event._.rejected`.
///   Stream SKYLANE_EVENTS, each event with a message id so a repeat is dropped.
/// - Approval requests: `skylane.approve.<operator>.<id>`, stream SKYLANE_APPROVALS, a work queue
///   (each request taken by one worker, removed once done).
/// - Buckets: skylane_flights (a flight's checkpoint: state, route, the fix sequence it covers),
///   skylane_partitions (each partition's checkpoint and the partition count), skylane_leases
///   (which worker holds a partition; keys expire unless refreshed), skylane_approvals (status,
///   report bundle and route of each approval, by operator and id), skylane_zonesets (zone sets
///   by `<owner>.<name>`, owner `authority` or an operator; each put a new version, the last 64 kept).

#include "service/nats_client.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace skylane::service::nats {

inline const std::string kFixStream = "SKYLANE_FIXES";
inline const std::string kEventStream = "SKYLANE_EVENTS";
inline const std::string kApprovalStream = "SKYLANE_APPROVALS";
inline const std::string kFlightBucket = "skylane_flights";
inline const std::string kPartitionBucket = "skylane_partitions";
inline const std::string kLeaseBucket = "skylane_leases";
inline const std::string kApprovalBucket = "skylane_approvals";
inline const std::string kZoneSetBucket = "skylane_zonesets";
inline const std::string kRejectedSubject = "skylane.event._.rejected";
inline constexpr int kLeaseTtl_s = 5;  ///< a partition whose worker stopped refreshing is free after this

/// \brief Whether `s` may be an operator, flight or approval id: 1–64 of A–Z a–z 0–9 `-` `_`,
/// not starting with `_` (a NATS subject token and a key-value key both).
[[nodiscard]] bool validId(std::string_view s);
/// \brief The subject a fix of `flight` is published to.
[[nodiscard]] std::string fixSubject(const std::string& op, const std::string& flight);
/// \brief The subject a partition's fixes arrive on after the server's mapping, with wildcards.
[[nodiscard]] std::string partitionFilter(int partition);
[[nodiscard]] std::string eventSubject(const std::string& op, const std::string& flight);
[[nodiscard]] std::string approvalSubject(const std::string& op, const std::string& id);
/// \brief The partition the server's mapping (serverMappings) sends `flight`'s fixes to: its
/// `partition(n,1,2)` transform, FNV-1a (32 bits) of the operator and flight tokens one after
/// the other, modulo `partitions` (tested against nats-server).
[[nodiscard]] int partitionOf(std::string_view op, std::string_view flight, int partitions);
/// \brief The server configuration's `mappings` block that spreads fixes over `partitions`.
[[nodiscard]] std::string serverMappings(int partitions);
/// \brief Makes (or checks) every stream and bucket; records the partition count, or checks it
/// against the one recorded. \throws NatsError, std::invalid_argument for another count.
void setUp(NatsClient& nats, int partitions);
/// \brief The partition count recorded by setUp. \throws std::invalid_argument when none is.
[[nodiscard]] int partitionCount(NatsClient& nats);

/// \brief The tokens of a subject split at dots.
[[nodiscard]] std::vector<std::string> subjectTokens(const std::string& subject);

}  // namespace skylane::service::nats
