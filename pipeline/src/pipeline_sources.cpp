// The pipeline's input side: ingest (one entry point for push(), driver threads and ring readers), the
// driver threads (pcap / live UDP through SensorDriver) and the shared-memory ring readers.
#include "pipeline_impl.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>

namespace rigcal::pipeline {

void Pipeline::Impl::ingest(Scan&& scan, int sensor, std::int64_t t0_ns) {
  if (sensor < 0) {
    unknown_sensor_scans.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (sensor == 0) {
    mapping_scans.fetch_add(1, std::memory_order_relaxed);
    mapping_lost_packets.fetch_add(scan.missing_packets, std::memory_order_relaxed);
  } else {
    lanes[std::size_t(sensor - 1)]->scans.fetch_add(1, std::memory_order_relaxed);
    lanes[std::size_t(sensor - 1)]->lost_packets.fetch_add(scan.missing_packets, std::memory_order_relaxed);
  }
  ScanItem item{std::make_shared<Scan>(std::move(scan)), sensor, t0_ns, false};
  if (realtime) q_in.pushDropOldest(std::move(item));
  else if (!q_in.push(std::move(item))) return;
  rec_ingest.record(t0_ns);
  wake_deskew.signal();
}

void Pipeline::Impl::endOfInput() {
  q_in.push(ScanItem{nullptr, -1, steadyNs(), true});
  wake_deskew.signal();
}

void Pipeline::Impl::waitForMappingLead(TimeNs stamp) {
  std::unique_lock lock(lead_mutex);
  lead_cv.wait(lock, [&] {
    return mapping_source_done || source_stop.load() || stamp <= mapping_ingested_stamp + kCalibrationLeadNs;
  });
}

void Pipeline::Impl::mappingIngested(TimeNs stamp, bool done) {
  {
    std::lock_guard lock(lead_mutex);
    if (done) mapping_source_done = true;
    else mapping_ingested_stamp = std::max(mapping_ingested_stamp, stamp);
  }
  lead_cv.notify_all();
}

void Pipeline::Impl::setUpSources() {
  if (isRecording(options.input) || options.input == InputKind::kLive) {
    DriverInput in;
    if (options.input == InputKind::kPcap) in.pcap = options.pcap;
    if (options.input == InputKind::kBag) in.bag = options.bag;
    if (isRecording(options.input)) in.rate = options.rate;
    for (const auto& [name, topic] : options.bag_topics)
      if (name.empty() ? sensors.size() != 1 : std::find(sensors.begin(), sensors.end(), name) == sensors.end())
        throw std::runtime_error(name.empty() ? "a bag topic without a sensor name (" + topic +
                                                    ") needs a one-sensor rig: give SENSOR=TOPIC"
                                              : "a bag topic for '" + name + "', which is not a sensor of the rig");
    const bool throttle = isRecording(options.input) && !realtime;
    for (std::size_t s = 0; s < sensors.size(); ++s) {
      const int sensor = int(s);
      const std::size_t d = drivers.size();  // the vector is complete before any driver thread starts
      if (const auto t = options.bag_topics.find(sensors[s]); t != options.bag_topics.end()) in.topic = t->second;
      else if (const auto any = options.bag_topics.find(""); any != options.bag_topics.end()) in.topic = any->second;
      else in.topic.clear();
      drivers.push_back(std::make_unique<SensorDriver>(
          rig.sensor(sensors[s]), in, source_stop, [this, sensor, d, throttle](Scan&& scan) {
            const std::int64_t t0 = steadyNs();
            if (throttle && sensor > 0) waitForMappingLead(scan.stamp_ns);
            const TimeNs stamp = scan.stamp_ns;
            // Malformed packets as they happen (on the driver's own thread, which owns its counters).
            const std::uint64_t malformed = drivers[d]->assemblerStats().malformed + drivers[d]->sourceStats().malformed;
            (sensor == 0 ? mapping_malformed_packets : lanes[std::size_t(sensor - 1)]->malformed_packets)
                .store(malformed, std::memory_order_relaxed);
            ingest(std::move(scan), sensor, t0);
            if (throttle && sensor == 0) mappingIngested(stamp, false);
          }));
      driver_sensor.push_back(sensor);
    }
  } else if (options.input == InputKind::kShm) {
    for (const auto& name : sensors) {
      shm::ReaderOptions ro;
      ro.sensor = name;
      ro.name_prefix = options.shm_prefix;
      ro.start_at = realtime ? shm::ReaderOptions::StartAt::kNext : shm::ReaderOptions::StartAt::kOldest;
      readers.push_back(std::make_unique<shm::ScanRingReader>(ro));
      ring_tallies.push_back(std::make_unique<RingInputTally>());
    }
  }
}

void Pipeline::Impl::startSources() {
  std::lock_guard lock(sources_mutex);
  for (std::size_t d = 0; d < drivers.size(); ++d) {
    ++sources_running;
    sources.emplace_back("drv:" + sensors[std::size_t(driver_sensor[d])], options.cores, [this, d] {
      drivers[d]->run();
      if (driver_sensor[d] == 0) mappingIngested(0, true);
      --sources_running;
    });
  }
  for (std::size_t r = 0; r < readers.size(); ++r) {
    ++sources_running;
    sources.emplace_back("shm:" + sensors[r], options.cores, [this, r] {
      readRing(r);
      --sources_running;
    });
  }
}

// One ring's reader thread. The reader follows a restarted writer (in place: a new epoch, or a new segment)
// by itself; here a writer that goes away and one that comes back are reported per sensor with the gap,
// and the input ends once every writer seen is gone (unless options.wait_for_writers).
void Pipeline::Impl::readRing(std::size_t r) {
  const std::string& sensor = sensors[r];
  shm::ScanRingReader& reader = *readers[r];
  Scan scan;
  shm::ScanMeta meta;
  bool live = false;                 // this ring's writer is counted in live_writers
  std::int64_t last_publish_ns = 0;  // CLOCK_MONOTONIC of the last scan read, 0 before the first
  std::uint64_t restarts = 0;
  std::uint64_t epoch = 0;  // of the last scan read
  RingInputTally& tally = *ring_tallies[r];
  const auto writerGone = [&](const std::string& why, bool clean) {
    live = false;
    std::cerr << (clean ? "" : "warning: ") << "sensor '" << sensor << "': " << why << "\n";
    if (--live_writers == 0 && !options.wait_for_writers && !source_stop.load()) {
      std::cerr << "every ring writer is gone: input ends (--wait-for-writers waits for new ones)\n";
      writers_gone.store(true);
    }
  };
  try {
    while (!source_stop.load() && !writers_gone.load()) {
      const auto st = reader.read(scan, std::chrono::milliseconds(100), &meta);
      if (st == shm::ReadStatus::kScan) {
        const bool restarted = reader.stats().writer_restarts != restarts;
        restarts = reader.stats().writer_restarts;
        if ((!live || restarted) && last_publish_ns != 0)
          std::cerr << "warning: sensor '" << sensor << "': a new writer (epoch " << meta.epoch << ") after a gap of "
                    << std::fixed << std::setprecision(2) << toSeconds(meta.publish_ns - last_publish_ns)
                    << std::defaultfloat << " s without scans\n";
        if (!live) ++live_writers;
        live = true;
        last_publish_ns = meta.publish_ns;
        // The writer's malformed packets as they happen, as an in-process driver's are shown.
        tally.update(meta.driver, meta.writer_scan, restarted || (epoch != 0 && meta.epoch != epoch));
        epoch = meta.epoch;
        (r == 0 ? mapping_malformed_packets : lanes[r - 1]->malformed_packets)
            .store(tally.totals().malformed, std::memory_order_relaxed);
        ingest(Scan(scan), int(r), meta.publish_ns);
      } else if (st == shm::ReadStatus::kWriterGone && live) {
        const shm::WriterStatus status = reader.writerStatus();
        writerGone(std::string("the writer of its ring is ") + shm::toString(status),
                   status == shm::WriterStatus::kClosed);
      }
    }
  } catch (const std::exception& e) {  // a ring truncated or replaced by a foreign one: this input ends
    if (live) writerGone(e.what(), false);
    else std::cerr << "warning: sensor '" << sensor << "': " << e.what() << "\n";
  }
}

// Stops the driver threads / ring readers and waits for them (caller holds finish_mutex).
void Pipeline::Impl::stopSources() {
  source_stop.store(true);
  lead_cv.notify_all();
  std::lock_guard sources_lock(sources_mutex);
  for (auto& s : sources) s.join();
}

}  // namespace rigcal::pipeline
