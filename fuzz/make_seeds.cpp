// make_seeds DATA_DIR RIGS_DIR OUT_DIR: small fuzz seeds cut from the real captures, made at fuzz time
// (nothing binary is committed). Writes
//   OUT/pcap/      the first records of every capture as a small pcap (µs and ns variants)
//   OUT/frames/    fuzz_link_layer input: [selector:1][length:2 BE][frame] records of consecutive frames
//   OUT/rig/       the rig YAML files
//   OUT/payloads/<vendor>/  single UDP payloads (reassembled) for the decoder harnesses
#include <pcap/pcap.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "rigcal/drivers/pcap_source.hpp"

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kPcapSeedBytes = 24 * 1024;  // per seed file, at least two records
constexpr std::size_t kFrameSeedRecords = 8;
constexpr std::size_t kPayloadsPerCapture = 6;

void put32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xff));  // little-endian pcap
}
void put16(std::string& out, std::uint16_t v) {
  out.push_back(char(v & 0xff));
  out.push_back(char(v >> 8));
}

void writeFile(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// The selector fuzz_link_layer maps to a link type: index into {Ethernet, Raw, SLL, SLL2, IPv4}.
int selectorFor(int dlt) {
  switch (dlt) {
    case DLT_EN10MB: return 0;
    case DLT_RAW: return 1;
    case DLT_LINUX_SLL: return 2;
    case DLT_LINUX_SLL2: return 3;
    case DLT_IPV4: return 4;
    default: return -1;
  }
}

void seedsFromCapture(const fs::path& capture, const fs::path& out, int index) {
  char err[PCAP_ERRBUF_SIZE] = {};
  pcap_t* handle = pcap_open_offline_with_tstamp_precision(capture.c_str(), PCAP_TSTAMP_PRECISION_NANO, err);
  if (!handle) {
    std::cerr << "make_seeds: skipping " << capture << ": " << err << '\n';
    return;
  }
  const int dlt = pcap_datalink(handle);
  const bool nano = index % 2 == 1;  // alternate the two classic pcap time resolutions
  std::string pcap_seed;
  put32(pcap_seed, nano ? 0xa1b23c4d : 0xa1b2c3d4);
  put16(pcap_seed, 2);
  put16(pcap_seed, 4);
  put32(pcap_seed, 0);
  put32(pcap_seed, 0);
  put32(pcap_seed, 65535);
  put32(pcap_seed, std::uint32_t(dlt));
  std::string frames;
  std::size_t records = 0;
  pcap_pkthdr* header = nullptr;
  const std::uint8_t* data = nullptr;
  while (pcap_next_ex(handle, &header, &data) == 1) {
    const bool want_pcap = records < 2 || pcap_seed.size() + 16 + header->caplen <= kPcapSeedBytes;
    if (want_pcap) {
      put32(pcap_seed, std::uint32_t(header->ts.tv_sec));
      put32(pcap_seed, std::uint32_t(nano ? header->ts.tv_usec : header->ts.tv_usec / 1000));
      put32(pcap_seed, header->caplen);
      put32(pcap_seed, header->len);
      pcap_seed.append(reinterpret_cast<const char*>(data), header->caplen);
    }
    if (records < kFrameSeedRecords && selectorFor(dlt) >= 0 && header->caplen <= 0xffff) {
      frames.push_back(char(selectorFor(dlt)));
      frames.push_back(char(header->caplen >> 8));
      frames.push_back(char(header->caplen & 0xff));
      frames.append(reinterpret_cast<const char*>(data), header->caplen);
    }
    ++records;
    if (!want_pcap && records >= kFrameSeedRecords) break;
  }
  pcap_close(handle);
  const std::string stem = capture.parent_path().filename().string() + "_" + capture.stem().string();
  writeFile(out / "pcap" / (stem + ".pcap"), pcap_seed);
  if (!frames.empty()) writeFile(out / "frames" / (stem + ".frames"), frames);

  // Whole UDP payloads, as a live socket would deliver them.
  try {
    rigcal::drivers::PcapSource source(capture);
    const fs::path dir = out / "payloads" / capture.parent_path().filename();
    fs::create_directories(dir);
    std::size_t n = 0;
    while (auto p = source.next()) {
      // The first few datagrams of the capture, whatever their port (data, position, telemetry).
      writeFile(dir / (stem + "_" + std::to_string(n) + ".bin"),
                std::string(reinterpret_cast<const char*>(p->payload.data()), p->payload.size()));
      if (++n >= kPayloadsPerCapture) break;
    }
  } catch (const std::exception& e) {
    std::cerr << "make_seeds: no payloads from " << capture << ": " << e.what() << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: make_seeds DATA_DIR RIGS_DIR OUT_DIR\n";
    return 2;
  }
  const fs::path data = argv[1], rigs = argv[2], out = argv[3];
  fs::remove_all(out);
  for (const char* sub : {"pcap", "frames", "rig", "payloads"}) fs::create_directories(out / sub);

  int index = 0;
  for (const char* vendor : {"velodyne", "ouster", "hesai", "robosense"}) {
    if (!fs::is_directory(data / vendor)) continue;
    for (const auto& entry : fs::directory_iterator(data / vendor))
      if (entry.path().extension() == ".pcap") seedsFromCapture(entry.path(), out, index++);
  }
  if (index == 0) std::cerr << "make_seeds: no captures under " << data << " (set RIGCAL_DATA_DIR)\n";
  if (fs::is_directory(rigs))
    for (const auto& entry : fs::directory_iterator(rigs))
      if (entry.path().extension() == ".yaml") fs::copy_file(entry.path(), out / "rig" / entry.path().filename());
  std::cout << "make_seeds: seeds from " << index << " captures in " << out << '\n';
  return 0;
}
