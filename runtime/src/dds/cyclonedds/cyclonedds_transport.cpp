#include "dds/cyclonedds/cyclonedds_transport.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <dds/ddsi/ddsi_serdata.h>
#include <fmt/format.h>

#include "core/executor.hpp"
#include "core/shutdown_signal.hpp"
#include "dds/cyclonedds/cyclonedds_qos.hpp"
#include "dds/cyclonedds/cyclonedds_reader_history.hpp"
#include "dds/cyclonedds/cyclonedds_type_support.hpp"
#include "dds/dds_options.hpp"
#include "dds/writer_backpressure.hpp"
#include "messages/message_pool.hpp"

namespace mocap {
namespace fs = std::filesystem;

namespace {

// Set while this thread is inside one of our own DDS writes: Cyclone delivers to the readers
// of other participants in this process on the writing thread, and those notifications must
// not run subscriber code inside the publisher's publish().
thread_local bool writing = false;

std::string error_text(dds_return_t code) { return dds_strretcode(code); }

std::string guid_text(const dds_guid_t& guid) {
  std::string text;
  for (size_t i = 0; i < 12; ++i) text += fmt::format("{:02x}{}", guid.v[i], i % 4 == 3 ? "." : "");
  text.pop_back();
  return text;
}

bool same_participant(const dds_guid_t& a, const dds_guid_t& b) {
  return std::memcmp(a.v, b.v, 12) == 0;  // the GUID prefix
}

}  // namespace

// ---------------------------------------------------------------------------------------

// A Cyclone domain of this process, configured once and shared by its participants: deleting
// a domain entity deletes every participant in it.
class CycloneDdsTransport::Domain {
 public:
  static std::shared_ptr<Domain> acquire(int id, const DdsOptions& options) {
    static std::mutex mutex;
    static std::map<int, std::weak_ptr<Domain>> domains;
    std::lock_guard lock(mutex);
    std::string configuration = domain_configuration(options);
    if (auto existing = domains[id].lock()) {
      if (existing->configuration_ != configuration) {
        throw std::runtime_error(fmt::format(
            "Cyclone DDS domain {} is already configured differently in this process (one "
            "configuration per domain and process: are the security settings the same?)",
            id));
      }
      return existing;
    }
    // The user's CYCLONEDDS_URI (files or XML), if any, comes last: its settings win.
    std::string full = configuration;
    const char* uri = std::getenv("CYCLONEDDS_URI");
    if (uri != nullptr && *uri != '\0') full += std::string(",") + uri;
    dds_entity_t entity = dds_create_domain(static_cast<dds_domainid_t>(id), full.c_str());
    if (entity < 0) {
      throw std::runtime_error(
          fmt::format("cannot create Cyclone DDS domain {}: {}{}", id, error_text(entity),
                      uri != nullptr && *uri != '\0'
                          ? fmt::format(" (is CYCLONEDDS_URI='{}' a valid configuration?)", uri)
                          : ""));
    }
    auto domain = std::shared_ptr<Domain>(new Domain(entity, std::move(configuration)));
    domains[id] = domain;
    return domain;
  }

  ~Domain() { dds_delete(entity_); }

 private:
  Domain(dds_entity_t entity, std::string configuration)
      : entity_(entity), configuration_(std::move(configuration)) {}
  dds_entity_t entity_;
  std::string configuration_;
};

// ---------------------------------------------------------------------------------------

class CycloneDdsTransport::Writer final : public TransportPublisher {
 public:
  Writer(CycloneDdsTransport& transport, const Endpoint& endpoint)
      : transport_(transport),
        endpoint_(endpoint),
        backpressure_(endpoint_, transport.stopped_waiting_, [this] { return subscribers(); }) {
    topic_ = transport.create_topic(endpoint);
    QosHandle qos;
    to_cyclone_writer_qos(endpoint.qos, qos.qos);
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_publication_matched(listener, &Writer::on_publication_matched);
    dds_lset_offered_incompatible_qos(listener, &Writer::on_offered_incompatible_qos);
    writer_ = dds_create_writer(transport.participant_, topic_, qos.qos, listener);
    dds_delete_listener(listener);
    if (writer_ < 0) {
      transport.delete_topic(endpoint, topic_);
      throw std::runtime_error(fmt::format("cannot create a DDS writer for {}{}", endpoint.topic,
                                           transport.access_hint("publish", writer_)));
    }
  }

  ~Writer() override {
    backpressure_.deliver_what_was_written(remote_readers_.load(), [this](auto slice) {
      return dds_wait_for_acks(writer_, std::chrono::nanoseconds(slice).count()) == DDS_RETCODE_OK;
    });
    dds_set_listener(writer_, nullptr);
    dds_delete(writer_);
    transport_.delete_topic(endpoint_, topic_);
  }

  // Cyclone's write waits while the writer holds more unacknowledged data than its high-water
  // mark (a reader with a full keep-all history does not acknowledge).
  void publish(const std::shared_ptr<const void>& message, Clock::time_point) override {
    if (backpressure_.nobody_needs_it(remote_readers_.load())) return;
    writing = true;
    dds_return_t result =
        backpressure_.write([&] { return dds_write(writer_, message.get()); },
                            [](dds_return_t code) { return code == DDS_RETCODE_TIMEOUT; });
    writing = false;
    if (result != DDS_RETCODE_OK && result != DDS_RETCODE_TIMEOUT) {
      backpressure_.count_failed_write(fmt::format("DDS write failed ({})", error_text(result)));
    }
  }

  size_t matched_subscribers() const override {
    return static_cast<size_t>(remote_readers_.load());
  }

  PublisherStats stats() const override { return backpressure_.stats(); }

 private:
  static void on_publication_matched(dds_entity_t, const dds_publication_matched_status_t status,
                                     void* self) {
    static_cast<Writer*>(self)->remote_readers_.store(static_cast<int>(status.current_count));
  }

  static void on_offered_incompatible_qos(dds_entity_t,
                                          const dds_offered_incompatible_qos_status_t status,
                                          void* self) {
    auto& writer = *static_cast<Writer*>(self);
    Logger(writer.endpoint_.owner)
        .warn(
            "{}: a DDS subscriber requests QoS this publisher ({}) does not offer (policy id "
            "{}); it receives nothing",
            writer.endpoint_.topic, writer.endpoint_.qos.to_string(), status.last_policy_id);
  }

  // "DDS subscriber(s) in 'sink', 'recorder'": the participants of the matched readers.
  std::string subscribers() const {
    std::set<std::string> names;
    dds_instance_handle_t handles[64];
    dds_return_t count = dds_get_matched_subscriptions(writer_, handles, 64);
    for (dds_return_t i = 0; i < std::min<dds_return_t>(count, 64); ++i) {
      if (dds_builtintopic_endpoint_t* reader =
              dds_get_matched_subscription_data(writer_, handles[i])) {
        names.insert(transport_.participant_name(reader->participant_key));
        dds_builtintopic_free_endpoint(reader);
      }
    }
    if (names.empty()) return "a DDS subscriber";
    return fmt::format("DDS subscriber(s) in '{}'", fmt::join(names, "', '"));
  }

  CycloneDdsTransport& transport_;
  Endpoint endpoint_;
  WriterBackpressure backpressure_;
  dds_entity_t topic_ = 0;
  dds_entity_t writer_ = 0;
  std::atomic<int> remote_readers_{0};
};

// ---------------------------------------------------------------------------------------

class CycloneDdsTransport::Reader final : public TransportSubscription {
 public:
  Reader(CycloneDdsTransport& transport, const Endpoint& endpoint, DataNotification on_data)
      : transport_(transport),
        endpoint_(endpoint),
        on_data_(std::move(on_data)),
        pool_(std::make_shared<MessagePool>(*endpoint.type)),
        drops_(endpoint, "subscriber") {
    topic_ = transport.create_topic(endpoint);
    QosHandle qos;
    to_cyclone_reader_qos(endpoint.qos, qos.qos);
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_data_available(listener, &Reader::on_data_available);
    dds_lset_sample_lost(listener, &Reader::on_sample_lost);
    dds_lset_sample_rejected(listener, &Reader::on_sample_rejected);
    dds_lset_requested_incompatible_qos(listener, &Reader::on_requested_incompatible_qos);
    history_ = make_cyclone_reader_history();
    reader_ =
        dds_create_reader_rhc(transport.participant_, topic_, qos.qos, listener, as_rhc(history_));
    dds_delete_listener(listener);
    if (reader_ < 0) {
      free_if_unused(history_);
      transport.delete_topic(endpoint, topic_);
      throw std::runtime_error(fmt::format("cannot create a DDS reader for {}{}", endpoint.topic,
                                           transport.access_hint("subscribe to", reader_)));
    }
  }

  ~Reader() override {
    dds_set_listener(reader_, nullptr);
    close(history_);
    dds_delete(reader_);
    transport_.delete_topic(endpoint_, topic_);
  }

  bool take(ReceivedMessage& out) override {
    for (;;) {
      ddsi_serdata* serdata = nullptr;
      dds_sample_info_t info{};
      if (dds_takecdr(reader_, &serdata, 1, &info, DDS_ANY_STATE) <= 0) return false;
      std::unique_ptr<ddsi_serdata, void (*)(ddsi_serdata*)> held(
          serdata, [](ddsi_serdata* d) { ddsi_serdata_unref(d); });
      if (!info.valid_data || from_volatile_publisher(info.publication_handle)) continue;
      std::shared_ptr<void> message = pool_->get();
      try {
        endpoint_.type->deserialize(serialized_bytes(serdata), message.get());
      } catch (const SerializationError&) {
        drops_.count(1, "malformed serialized data");
        continue;
      } catch (const std::bad_alloc&) {
        drops_.count(1, "malformed serialized data");
        continue;
      }
      out.message = std::move(message);
      out.source_time = Clock::time_point(std::chrono::duration_cast<Clock::duration>(
          std::chrono::nanoseconds(info.source_timestamp)));
      return true;
    }
  }

  uint64_t dropped() const override { return drops_.total(); }
  // Cyclone DDS has no count of a reader's unread samples short of reading them.
  std::optional<size_t> waiting() const override { return std::nullopt; }

 private:
  static void on_data_available(dds_entity_t, void* self) {
    static_cast<Reader*>(self)->on_data_(!writing);
  }

  static void on_sample_lost(dds_entity_t, const dds_sample_lost_status_t status, void* self) {
    static_cast<Reader*>(self)->drops_.count(static_cast<uint64_t>(status.total_count_change),
                                             "lost in transit (best effort)");
  }

  static void on_sample_rejected(dds_entity_t, const dds_sample_rejected_status_t status,
                                 void* self) {
    auto& reader = *static_cast<Reader*>(self);
    auto count = static_cast<uint64_t>(status.total_count_change);
    if (reader.endpoint_.qos.reliability == Reliability::BestEffort) {
      reader.drops_.count(count, "rejected: the subscriber's queue is full");
    } else if (reader.holding_back_.count(count)) {
      Logger(reader.endpoint_.owner)
          .info(
              "{}: subscriber '{}' has {} samples waiting to be taken; its DDS publishers wait "
              "for it (reliable, keep_all)",
              reader.endpoint_.topic, reader.endpoint_.owner, reader.endpoint_.qos.depth);
    }
  }

  static void on_requested_incompatible_qos(dds_entity_t,
                                            const dds_requested_incompatible_qos_status_t status,
                                            void* self) {
    auto& reader = *static_cast<Reader*>(self);
    Logger(reader.endpoint_.owner)
        .warn(
            "{}: a DDS publisher does not offer the QoS this subscriber requests ({}; policy id "
            "{}); nothing arrives from it",
            reader.endpoint_.topic, reader.endpoint_.qos.to_string(), status.last_policy_id);
  }

  // A transient-local subscriber matches volatile reliable publishers, which are
  // transient-local on the wire (to_cyclone_writer_qos says why), but must not take from them, as
  // in one process it is not connected to them.
  bool from_volatile_publisher(dds_instance_handle_t publication) {
    if (endpoint_.qos.durability != Durability::TransientLocal) return false;
    auto known = volatile_publishers_.find(publication);
    if (known != volatile_publishers_.end()) return known->second;
    dds_builtintopic_endpoint_t* writer = dds_get_matched_publication_data(reader_, publication);
    if (writer == nullptr) return false;
    Qos offered = qos_from_cyclone(writer->qos);
    bool is_volatile = offered.durability == Durability::Volatile;
    if (is_volatile) {
      Logger(endpoint_.owner)
          .warn("{}: not connected to the publisher in '{}': {}", endpoint_.topic,
                transport_.participant_name(writer->participant_key),
                *qos_mismatch(offered, endpoint_.qos));
    }
    dds_builtintopic_free_endpoint(writer);
    volatile_publishers_[publication] = is_volatile;
    return is_volatile;
  }

  CycloneDdsTransport& transport_;
  Endpoint endpoint_;
  DataNotification on_data_;
  std::shared_ptr<MessagePool> pool_;
  DropReport drops_;
  Throttle holding_back_{std::chrono::seconds(10)};
  std::map<dds_instance_handle_t, bool> volatile_publishers_;  // used by take() only
  dds_entity_t topic_ = 0;
  CycloneReaderHistory* history_ = nullptr;  // owned by the reader
  dds_entity_t reader_ = 0;
};

// ---------------------------------------------------------------------------------------

CycloneDdsTransport::CycloneDdsTransport(const DdsOptions& given,
                                         const std::string& participant_name)
    : domain_id_(resolve_domain_id(given.domain_id)) {
  DdsOptions options = with_environment(given);
  domain_ = Domain::acquire(domain_id_, options);
  QosHandle qos;
  dds_qset_entity_name(qos.qos, participant_name.c_str());
  participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain_id_), qos.qos, nullptr);
  if (participant_ < 0) {
    throw std::runtime_error(
        options.security_directory.empty()
            ? fmt::format("cannot create a Cyclone DDS participant on domain {}: {}", domain_id_,
                          error_text(participant_))
            : fmt::format("cannot create a DDS participant on domain {} as DDS Security "
                          "identity '{}' of {}: {} (Cyclone DDS's log above says why)",
                          domain_id_, options.security_identity, options.security_directory,
                          error_text(participant_)));
  }
  secure_ = !options.security_directory.empty();
  dds_get_guid(participant_, &own_guid_);
  // Cyclone fills a builtin-topic reader with what discovery knows and keeps it up to date.
  participants_ =
      dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
  publications_ =
      dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  subscriptions_ =
      dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
  if (participants_ < 0 || publications_ < 0 || subscriptions_ < 0) {
    dds_delete(participant_);
    throw std::runtime_error("cannot read Cyclone DDS's discovery (builtin topics)");
  }
}

CycloneDdsTransport::~CycloneDdsTransport() { dds_delete(participant_); }

std::unique_ptr<TransportPublisher> CycloneDdsTransport::advertise(const Endpoint& endpoint) {
  return std::make_unique<Writer>(*this, endpoint);
}

std::unique_ptr<TransportSubscription> CycloneDdsTransport::subscribe(const Endpoint& endpoint,
                                                                      DataNotification on_data) {
  return std::make_unique<Reader>(*this, endpoint, std::move(on_data));
}

void CycloneDdsTransport::stop_waiting() { stopped_waiting_.store(true); }

std::string CycloneDdsTransport::access_hint(std::string_view action, dds_return_t error) const {
  if (secure_) {
    return fmt::format(" (DDS Security is on: do this identity's permissions let it {} the topic?)",
                       action);
  }
  return ": " + error_text(error);
}

dds_entity_t CycloneDdsTransport::create_topic(const Endpoint& endpoint) {
  std::string name = dds_topic_name(endpoint.topic);
  {
    std::lock_guard lock(mutex_);
    auto [it, added] = topic_types_.try_emplace(name, endpoint.type->dds_name(), 0);
    if (!added && it->second.first != endpoint.type->dds_name()) {
      throw std::invalid_argument(fmt::format(
          "topic '{}' is already used with type {} here; '{}' uses it with {}", endpoint.topic,
          ros_type_name(it->second.first), endpoint.owner, endpoint.type->name()));
    }
    ++it->second.second;
  }
  ddsi_sertype* sertype = make_cyclonedds_sertype(*endpoint.type);
  dds_entity_t topic =
      dds_create_topic_sertype(participant_, name.c_str(), &sertype, nullptr, nullptr, nullptr);
  if (topic < 0) {
    delete_topic(endpoint, 0);
    throw std::runtime_error(fmt::format("cannot create DDS topic {} of type {}: {}", name,
                                         endpoint.type->dds_name(), error_text(topic)));
  }
  return topic;
}

void CycloneDdsTransport::delete_topic(const Endpoint& endpoint, dds_entity_t topic) {
  if (topic > 0) dds_delete(topic);
  std::lock_guard lock(mutex_);
  auto it = topic_types_.find(dds_topic_name(endpoint.topic));
  if (it != topic_types_.end() && --it->second.second == 0) topic_types_.erase(it);
}

namespace {

// Every alive sample `reader` of a builtin topic holds.
template <class Sample, class Visit>
void read_builtin(dds_entity_t reader, Visit visit) {
  constexpr size_t kMost = 4096;
  std::vector<void*> samples(kMost, nullptr);
  std::vector<dds_sample_info_t> infos(kMost);
  dds_return_t count =
      dds_read_mask(reader, samples.data(), infos.data(), kMost, kMost,
                    DDS_ANY_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ALIVE_INSTANCE_STATE);
  for (dds_return_t i = 0; i < count; ++i) {
    if (infos[i].valid_data) visit(*static_cast<const Sample*>(samples[i]));
  }
  if (count > 0) dds_return_loan(reader, samples.data(), count);
}

}  // namespace

std::string CycloneDdsTransport::participant_name(const dds_guid_t& key) const {
  std::string name;
  read_builtin<dds_builtintopic_participant_t>(
      participants_, [&](const dds_builtintopic_participant_t& participant) {
        char* announced = nullptr;
        if (same_participant(participant.key, key) &&
            dds_qget_entity_name(participant.qos, &announced) && announced != nullptr) {
          name = announced;
        }
        dds_free(announced);
      });
  return name.empty() ? guid_text(key) : name;
}

std::vector<DiscoveredEndpoint> CycloneDdsTransport::discovered_endpoints() const {
  std::map<std::string, std::string> names;  // participant GUID -> name
  read_builtin<dds_builtintopic_participant_t>(
      participants_, [&](const dds_builtintopic_participant_t& participant) {
        char* announced = nullptr;
        if (dds_qget_entity_name(participant.qos, &announced) && announced != nullptr) {
          names[guid_text(participant.key)] = announced;
        }
        dds_free(announced);
      });
  std::vector<DiscoveredEndpoint> out;
  for (bool publishers : {true, false}) {
    read_builtin<dds_builtintopic_endpoint_t>(
        publishers ? publications_ : subscriptions_,
        [&](const dds_builtintopic_endpoint_t& endpoint) {
          if (same_participant(endpoint.participant_key, own_guid_)) return;
          // Cyclone's own builtin endpoints are not announced this way; others' may be.
          if (endpoint.topic_name == nullptr || endpoint.type_name == nullptr) return;
          DiscoveredEndpoint found;
          found.topic = ros_topic_name(endpoint.topic_name);
          found.type = endpoint.type_name;
          found.is_publisher = publishers;
          found.qos = qos_from_cyclone(endpoint.qos);
          std::string key = guid_text(endpoint.participant_key);
          auto name = names.find(key);
          found.participant = name != names.end() ? name->second : key;
          out.push_back(std::move(found));
        });
  }
  return out;
}

}  // namespace mocap
