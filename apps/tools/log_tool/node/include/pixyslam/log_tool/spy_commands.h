#pragma once

#include <cstddef>
#include <ostream>
#include <string>

#include "pixyslam/dds/participant.h"

namespace pixyslam::log_tool {

// The live (DDS) subcommands of pixyslam_spy. Each joins the domain of `dds`
// with its own participant, runs for the time given (or until SIGINT/SIGTERM
// through app::StopSignal) and returns the exit status: 0 ok, 1 failure
// (e.g. fewer samples than --count before the time limit), 2 unknown topic.

// `json`: every command prints JSON lines (one object per line) instead of its
// table, with the same content.

// Every other DomainParticipant seen within `seconds`: name, GUID prefix and
// the pixyslam.host / pixyslam.pid / pixyslam.process properties.
int run_participants(const dds::DdsOptions& dds, double seconds, bool json, std::ostream& out);

// Every topic with its type and each writer/reader (participant, reliability,
// durability; history from the local XML profile: DDS does not announce it).
int run_topics(const dds::DdsOptions& dds, double seconds, bool json, std::ostream& out);

struct EchoRequest {
  std::string topic;
  bool json = false;       // JSON lines instead of YAML documents
  std::size_t count = 0;   // stop after this many samples (0: no limit)
  double seconds = 0.0;    // stop after this long (0: no limit); with count: failure if not reached
  std::string robot;       // only samples with this header.robot_id ("": every robot)
};
int run_echo(const dds::DdsOptions& dds, const EchoRequest& request, std::ostream& out);

// Message rate and inter-arrival gap statistics over `seconds` (0: until a signal).
// The latest pixyslam/diagnostics report of every process heard within `seconds`
// (diagnostics_table); exit status 1 if none.
int run_diagnostics(const dds::DdsOptions& dds, double seconds, bool json, std::ostream& out);
// `robot`: only samples with this header.robot_id ("": every robot).
int run_hz(const dds::DdsOptions& dds, const std::string& topic, double seconds, bool json, std::ostream& out,
           const std::string& robot = "");

}  // namespace pixyslam::log_tool
