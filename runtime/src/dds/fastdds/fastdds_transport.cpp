#include "dds/fastdds/fastdds_transport.hpp"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastrtps/rtps/builtin/data/ReaderProxyData.h>
#include <fastrtps/rtps/builtin/data/WriterProxyData.h>
#include <fmt/format.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "core/executor.hpp"
#include "core/shutdown_signal.hpp"
#include "dds/fastdds/fastdds_qos.hpp"
#include "dds/fastdds/fastdds_shared_memory.hpp"
#include "dds/fastdds/fastdds_type_adapter.hpp"
#include "dds/writer_backpressure.hpp"
#include "messages/message_pool.hpp"

namespace mocap {
namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

rtps::GuidPrefix_t prefix_of(const rtps::InstanceHandle_t& handle) {
  rtps::GUID_t guid;
  rtps::iHandle2GUID(guid, handle);
  return guid.guidPrefix;
}

// Set while this thread is inside one of our own DDS writes. Fast DDS hands a sample to the
// readers of the writer's own participant synchronously, on the writing thread; those
// notifications must not run subscriber code inside the publisher's publish().
thread_local bool writing = false;

Clock::time_point to_time_point(const rtps::Time_t& time) {
  return Clock::time_point(std::chrono::duration_cast<Clock::duration>(
      std::chrono::seconds(time.seconds()) + std::chrono::nanoseconds(time.nanosec())));
}

// Why creating an endpoint may have failed, when DDS Security's access control is on.
std::string access_control_hint(dds::DomainParticipant* participant, std::string_view action) {
  for (const auto& property : participant->get_qos().properties().properties()) {
    if (property.name() == "dds.sec.access.plugin") {
      return fmt::format(
          " (DDS Security is on: do this identity's permissions let it {} the topic?)", action);
    }
  }
  return "";
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Discovery: what other participants read and write, for tools such as `mocap_topic list`.

class FastDdsTransport::Listener final : public dds::DomainParticipantListener {
 public:
  void on_publisher_discovery(dds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    update(info.info, info.status == rtps::WriterDiscoveryInfo::DISCOVERED_WRITER ||
                          info.status == rtps::WriterDiscoveryInfo::CHANGED_QOS_WRITER);
  }

  void on_subscriber_discovery(dds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override {
    update(info.info, info.status == rtps::ReaderDiscoveryInfo::DISCOVERED_READER ||
                          info.status == rtps::ReaderDiscoveryInfo::CHANGED_QOS_READER);
  }

  void on_participant_discovery(dds::DomainParticipant*,
                                rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard lock(mutex_);
    auto prefix = info.info.m_guid.guidPrefix;
    if (info.status == rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
      participants_[prefix] = info.info.m_participantName.to_string();
    } else if (info.status == rtps::ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
               info.status == rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT) {
      participants_.erase(prefix);
      std::erase_if(endpoints_,
                    [&](const auto& entry) { return entry.first.guidPrefix == prefix; });
    }
  }

  // The name a participant announced, or its GUID prefix while it is not known.
  std::string participant_name(const rtps::GuidPrefix_t& prefix) const {
    std::lock_guard lock(mutex_);
    if (auto it = participants_.find(prefix); it != participants_.end()) return it->second;
    std::ostringstream text;
    text << prefix;
    return text.str();
  }

  // The discovered publisher `writer`, if it is known.
  std::optional<DiscoveredEndpoint> publisher(const rtps::GUID_t& writer) const {
    std::lock_guard lock(mutex_);
    auto it = endpoints_.find(writer);
    if (it == endpoints_.end() || !it->second.is_publisher) return std::nullopt;
    DiscoveredEndpoint copy = it->second;
    if (auto name = participants_.find(writer.guidPrefix); name != participants_.end()) {
      copy.participant = name->second;
    }
    return copy;
  }

  std::vector<DiscoveredEndpoint> endpoints() const {
    std::lock_guard lock(mutex_);
    std::vector<DiscoveredEndpoint> out;
    for (const auto& [guid, endpoint] : endpoints_) {
      DiscoveredEndpoint copy = endpoint;
      if (auto it = participants_.find(guid.guidPrefix); it != participants_.end()) {
        copy.participant = it->second;
      }
      out.push_back(std::move(copy));
    }
    return out;
  }

 private:
  // `data`: a WriterProxyData or a ReaderProxyData.
  template <class ProxyData>
  void update(const ProxyData& data, bool alive) {
    std::lock_guard lock(mutex_);
    if (!alive) {
      endpoints_.erase(data.guid());
      return;
    }
    DiscoveredEndpoint& endpoint = endpoints_[data.guid()];
    endpoint.topic = ros_topic_name(data.topicName().to_string());
    endpoint.type = data.typeName().to_string();
    endpoint.is_publisher = std::is_same_v<ProxyData, rtps::WriterProxyData>;
    endpoint.qos.reliability = data.m_qos.m_reliability.kind == dds::RELIABLE_RELIABILITY_QOS
                                   ? Reliability::Reliable
                                   : Reliability::BestEffort;
    Durability announced = data.m_qos.m_durability.kind == dds::TRANSIENT_LOCAL_DURABILITY_QOS
                               ? Durability::TransientLocal
                               : Durability::Volatile;
    endpoint.qos.durability = offered_durability(announced, data.m_qos.m_userData.data_vec());
  }

  mutable std::mutex mutex_;
  std::map<rtps::GUID_t, DiscoveredEndpoint> endpoints_;
  std::map<rtps::GuidPrefix_t, std::string> participants_;
};

// ---------------------------------------------------------------------------------------

class FastDdsTransport::Writer final : public TransportPublisher, public dds::DataWriterListener {
 public:
  Writer(FastDdsTransport& transport, const Endpoint& endpoint)
      : transport_(transport),
        endpoint_(endpoint),
        own_prefix_(transport.participant_->guid().guidPrefix),
        backpressure_(endpoint_, transport.stopped_waiting_, [this] { return subscribers(); }) {
    const TopicUse& use = transport.acquire_topic(endpoint);
    topic_ = use.topic;
    local_writers_ = use.local_writers;
    local_writers_->fetch_add(1);
    writer_ = transport.publisher_->create_datawriter(
        topic_, to_writer_qos(endpoint.qos), this,
        dds::StatusMask::publication_matched() << dds::StatusMask::offered_incompatible_qos());
    if (writer_ == nullptr) {
      local_writers_->fetch_sub(1);
      transport.release_topic(topic_);
      throw std::runtime_error(fmt::format("cannot create a DDS writer for {}{}", endpoint.topic,
                                           access_control_hint(transport.participant_, "publish")));
    }
  }

  ~Writer() override {
    backpressure_.deliver_what_was_written(remote_readers_.load(), [this](auto slice) {
      auto nanoseconds = std::chrono::duration_cast<std::chrono::nanoseconds>(slice).count();
      // Fast DDS 2.9 reports a timeout here as RETCODE_ERROR.
      return writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(
                 0, static_cast<uint32_t>(nanoseconds))) == ReturnCode_t::RETCODE_OK;
    });
    writer_->set_listener(nullptr);
    transport_.publisher_->delete_datawriter(writer_);
    local_writers_->fetch_sub(1);
    transport_.release_topic(topic_);
  }

  // Fast DDS wakes a waiting write as soon as acknowledgements free a sample, or the reader
  // goes away (unmatched: its acknowledgements no longer count). Fast DDS 2.9 also reports
  // timeouts before that when acks free a full keep-all history (a volatile writer removes the
  // acknowledged samples itself, and the waiting write, finding none left to remove, gives up
  // although there is room); writing again succeeds at once.
  void publish(const std::shared_ptr<const void>& message, Clock::time_point) override {
    if (backpressure_.nobody_needs_it(remote_readers_.load())) return;
    writing = true;
    ReturnCode_t result = backpressure_.write(
        [&] { return writer_->write(const_cast<void*>(message.get()), dds::HANDLE_NIL); },
        [](const ReturnCode_t& code) { return code == ReturnCode_t::RETCODE_TIMEOUT; });
    writing = false;
    if (result != ReturnCode_t::RETCODE_OK && result != ReturnCode_t::RETCODE_TIMEOUT) {
      backpressure_.count_failed_write(fmt::format("DDS write failed (code {})", result()));
    }
  }

  size_t matched_subscribers() const override {
    return static_cast<size_t>(remote_readers_.load());
  }

  PublisherStats stats() const override { return backpressure_.stats(); }

  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    rtps::GuidPrefix_t prefix = prefix_of(status.last_subscription_handle);
    if (prefix == own_prefix_) return;
    remote_readers_.fetch_add(status.current_count_change);
    std::lock_guard lock(matched_mutex_);
    if (status.current_count_change > 0) {
      matched_prefixes_.insert(prefix);
    } else if (auto it = matched_prefixes_.find(prefix); it != matched_prefixes_.end()) {
      matched_prefixes_.erase(it);
    }
  }

  void on_offered_incompatible_qos(dds::DataWriter*,
                                   const dds::OfferedIncompatibleQosStatus& status) override {
    Logger(endpoint_.owner)
        .warn(
            "{}: a DDS subscriber requests QoS this publisher ({}) does not offer (policy id "
            "{}); it receives nothing",
            endpoint_.topic, endpoint_.qos.to_string(), status.last_policy_id);
  }

 private:
  // "DDS subscriber(s) in 'sink', 'recorder'": the participants of the matched readers.
  // (Fast DDS 2.9 does not implement DataWriter::get_matched_subscriptions().)
  std::string subscribers() const {
    std::set<std::string> names;
    {
      std::lock_guard lock(matched_mutex_);
      for (const auto& prefix : matched_prefixes_) {
        names.insert(transport_.listener_->participant_name(prefix));
      }
    }
    if (names.empty()) return "a DDS subscriber";
    return fmt::format("DDS subscriber(s) in '{}'", fmt::join(names, "', '"));
  }

  FastDdsTransport& transport_;
  Endpoint endpoint_;
  rtps::GuidPrefix_t own_prefix_;
  WriterBackpressure backpressure_;
  dds::Topic* topic_ = nullptr;
  std::shared_ptr<std::atomic<int>> local_writers_;
  dds::DataWriter* writer_ = nullptr;
  std::atomic<int> remote_readers_{0};
  mutable std::mutex matched_mutex_;
  std::multiset<rtps::GuidPrefix_t> matched_prefixes_;  // of remote readers
};

// ---------------------------------------------------------------------------------------

class FastDdsTransport::Reader final : public TransportSubscription,
                                       public dds::DataReaderListener {
 public:
  Reader(FastDdsTransport& transport, const Endpoint& endpoint, DataNotification on_data)
      : transport_(transport),
        endpoint_(endpoint),
        on_data_(std::move(on_data)),
        pool_(std::make_shared<MessagePool>(*endpoint.type)),
        own_prefix_(transport.participant_->guid().guidPrefix),
        drops_(endpoint, "subscriber") {
    const TopicUse& use = transport.acquire_topic(endpoint);
    topic_ = use.topic;
    local_writers_ = use.local_writers;
    reader_ = transport.subscriber_->create_datareader(
        topic_, to_reader_qos(endpoint.qos), this,
        dds::StatusMask::data_available()
            << dds::StatusMask::sample_lost() << dds::StatusMask::sample_rejected()
            << dds::StatusMask::requested_incompatible_qos());
    if (reader_ == nullptr) {
      transport.release_topic(topic_);
      throw std::runtime_error(
          fmt::format("cannot create a DDS reader for {}{}", endpoint.topic,
                      access_control_hint(transport.participant_, "subscribe to")));
    }
  }

  ~Reader() override {
    reader_->set_listener(nullptr);
    transport_.subscriber_->delete_datareader(reader_);
    transport_.release_topic(topic_);
  }

  bool take(ReceivedMessage& out) override {
    dds::SampleInfo info;
    for (;;) {
      DdsSample sample;
      // Only when this process writes the topic too can the next sample be our own; then a
      // peek lets it be dropped without deserializing it.
      if (local_writers_->load() > 0) {
        if (reader_->get_first_untaken_info(&info) != ReturnCode_t::RETCODE_OK) return false;
        sample.skip = is_own(info);
      }
      if (!sample.skip) sample.message = pool_->get();
      if (reader_->take_next_sample(&sample, &info) != ReturnCode_t::RETCODE_OK) return false;
      // A sample can arrive between peeking and taking; judge what was actually taken.
      if (!info.valid_data || is_own(info)) continue;
      if (from_volatile_publisher(info)) continue;
      if (sample.skip) {
        drops_.count(1, "replaced in the reader queue while being taken");
        continue;
      }
      if (sample.malformed) {
        drops_.count(1, "malformed serialized data");
        continue;
      }
      out.message = std::move(sample.message);
      out.source_time = to_time_point(info.source_timestamp);
      return true;
    }
  }

  uint64_t dropped() const override { return drops_.total(); }
  std::optional<size_t> waiting() const override {
    return static_cast<size_t>(reader_->get_unread_count());
  }

  void on_data_available(dds::DataReader*) override { on_data_(!writing); }

  void on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& status) override {
    drops_.count(static_cast<uint64_t>(status.total_count_change), "lost in transit (best effort)");
  }

  // A reliable reader's rejected samples are sent again: its publishers wait for it. Only a
  // best-effort reader's are lost.
  void on_sample_rejected(dds::DataReader*, const dds::SampleRejectedStatus& status) override {
    auto count = static_cast<uint64_t>(status.total_count_change);
    if (endpoint_.qos.reliability == Reliability::BestEffort) {
      drops_.count(count, "rejected: the subscriber's queue is full");
    } else if (holding_back_.count(count)) {
      Logger(endpoint_.owner)
          .info(
              "{}: subscriber '{}' has {} samples waiting to be taken; its DDS publishers wait "
              "for it (reliable, keep_all)",
              endpoint_.topic, endpoint_.owner, endpoint_.qos.depth);
    }
  }

  void on_requested_incompatible_qos(dds::DataReader*,
                                     const dds::RequestedIncompatibleQosStatus& status) override {
    Logger(endpoint_.owner)
        .warn(
            "{}: a DDS publisher does not offer the QoS this subscriber requests ({}; policy id "
            "{}); nothing arrives from it",
            endpoint_.topic, endpoint_.qos.to_string(), status.last_policy_id);
  }

 private:
  bool is_own(const dds::SampleInfo& info) const {
    return info.sample_identity.writer_guid().guidPrefix == own_prefix_;
  }

  // A transient-local subscriber matches our volatile reliable publishers, which are
  // transient-local on the wire (to_writer_qos says why), but must not take from them, as in
  // one process it is not connected to them.
  bool from_volatile_publisher(const dds::SampleInfo& info) {
    if (endpoint_.qos.durability != Durability::TransientLocal) return false;
    const rtps::GUID_t& writer = info.sample_identity.writer_guid();
    std::optional<DiscoveredEndpoint> publisher = transport_.listener_->publisher(writer);
    if (!publisher || publisher->qos.durability != Durability::Volatile) return false;
    if (ignored_writers_.insert(writer).second) {
      Logger(endpoint_.owner)
          .warn("{}: not connected to the publisher in '{}': {}", endpoint_.topic,
                publisher->participant, *qos_mismatch(publisher->qos, endpoint_.qos));
    }
    return true;
  }

  FastDdsTransport& transport_;
  Endpoint endpoint_;
  DataNotification on_data_;
  std::shared_ptr<MessagePool> pool_;
  rtps::GuidPrefix_t own_prefix_;
  DropReport drops_;
  Throttle holding_back_{std::chrono::seconds(10)};
  std::set<rtps::GUID_t> ignored_writers_;  // used by take(), on the subscriber's strand
  dds::Topic* topic_ = nullptr;
  std::shared_ptr<std::atomic<int>> local_writers_;
  dds::DataReader* reader_ = nullptr;
};

// ---------------------------------------------------------------------------------------

FastDdsTransport::FastDdsTransport(const DdsOptions& options, const std::string& participant_name)
    : domain_id_(resolve_domain_id(options.domain_id)), listener_(std::make_unique<Listener>()) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos qos = to_participant_qos(options, participant_name);
  {
    // Until the participant holds its ports, another one in this process would choose them too.
    static std::mutex choosing_ports;
    std::lock_guard lock(choosing_ports);
    if (options.shared_memory) {
      remove_orphaned_shared_memory();
      if (auto id = unused_participant_id(domain_id_)) qos.wire_protocol().participant_id = *id;
    }
    participant_ =
        factory->create_participant(domain_id_, qos, listener_.get(), dds::StatusMask::none());
  }
  if (participant_ == nullptr) {
    DdsOptions used = with_environment(options);
    throw std::runtime_error(
        used.security_directory.empty()
            ? fmt::format("cannot create a DDS participant on domain {}", domain_id_)
            : fmt::format("cannot create a DDS participant on domain {} as DDS Security "
                          "identity '{}' of {} (Fast DDS's error above says why)",
                          domain_id_, used.security_identity, used.security_directory));
  }
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
    throw std::runtime_error("cannot create the DDS publisher and subscriber");
  }
}

FastDdsTransport::~FastDdsTransport() {
  participant_->set_listener(nullptr);
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

std::unique_ptr<TransportPublisher> FastDdsTransport::advertise(const Endpoint& endpoint) {
  return std::make_unique<Writer>(*this, endpoint);
}

std::unique_ptr<TransportSubscription> FastDdsTransport::subscribe(const Endpoint& endpoint,
                                                                   DataNotification on_data) {
  return std::make_unique<Reader>(*this, endpoint, std::move(on_data));
}

void FastDdsTransport::stop_waiting() { stopped_waiting_.store(true); }

std::vector<DiscoveredEndpoint> FastDdsTransport::discovered_endpoints() const {
  return listener_->endpoints();
}

const FastDdsTransport::TopicUse& FastDdsTransport::acquire_topic(const Endpoint& endpoint) {
  std::lock_guard lock(mutex_);
  std::string name = dds_topic_name(endpoint.topic);
  if (auto it = topics_.find(name); it != topics_.end()) {
    std::string used = it->second.topic->get_type_name();
    if (used != endpoint.type->dds_name()) {
      throw std::invalid_argument(
          fmt::format("topic '{}' is already used with type {} here; '{}' "
                      "uses it with {}",
                      endpoint.topic, ros_type_name(used), endpoint.owner, endpoint.type->name()));
    }
    ++it->second.users;
    return it->second;
  }
  if (participant_->find_type(endpoint.type->dds_name()).empty()) {
    dds::TypeSupport support(new DdsTypeAdapter(*endpoint.type));
    if (support.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error(
          fmt::format("cannot register type {} with DDS", endpoint.type->dds_name()));
    }
  }
  dds::Topic* topic =
      participant_->create_topic(name, endpoint.type->dds_name(), dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) {
    throw std::runtime_error(fmt::format("cannot create DDS topic {}", name));
  }
  TopicUse& use = topics_[name];
  use.topic = topic;
  use.users = 1;
  return use;
}

void FastDdsTransport::release_topic(dds::Topic* topic) {
  std::lock_guard lock(mutex_);
  auto it = topics_.find(topic->get_name());
  if (it == topics_.end() || --it->second.users > 0) return;
  participant_->delete_topic(topic);
  topics_.erase(it);
}

}  // namespace mocap
