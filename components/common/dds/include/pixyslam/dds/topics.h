#pragma once

#include <string_view>

#include "common.h"
#include "diagnostics.h"
#include "diagnosticsPubSubTypes.h"
#include "ground_truth.h"
#include "ground_truthPubSubTypes.h"
#include "landmark_observation.h"
#include "landmark_observationPubSubTypes.h"
#include "map_state.h"
#include "map_statePubSubTypes.h"
#include "odometry.h"
#include "odometryPubSubTypes.h"
#include "optimised_map.h"
#include "optimised_mapPubSubTypes.h"
#include "robot_sighting.h"
#include "robot_sightingPubSubTypes.h"
#include "fleet_map.h"
#include "fleet_mapPubSubTypes.h"

// The generated TypeObject registration functions (declared here rather than
// by including the generated *TypeObject.h headers: those put
// `using namespace eprosima::fastrtps::types;` at global scope, whose
// operator== templates then clash with Eigen's enum comparisons).
void registerodometryTypes();
void registerlandmark_observationTypes();
void registermap_stateTypes();
void registerground_truthTypes();
void registerdiagnosticsTypes();
void registeroptimised_mapTypes();
void registerrobot_sightingTypes();
void registerfleet_mapTypes();

namespace pixyslam::msg {
// IDL of idl/<stem>.idl with its includes inlined (an `omgidl` schema); "" if unknown.
std::string_view idl_text(std::string_view stem);
}  // namespace pixyslam::msg

namespace pixyslam::dds {

// Every topic of the system, in one place. The XML profiles (config/dds/) hold a
// data_writer and a data_reader profile named exactly like each topic: QoS lives
// there, not in code.
inline constexpr std::string_view kOdometryTopic = "pixyslam/odometry";
inline constexpr std::string_view kLandmarkObservationTopic = "pixyslam/landmark_observation";
inline constexpr std::string_view kMapStateTopic = "pixyslam/map_state";
inline constexpr std::string_view kGroundTruthTopic = "pixyslam/ground_truth";
inline constexpr std::string_view kDiagnosticsTopic = "pixyslam/diagnostics";
inline constexpr std::string_view kOptimisedMapTopic = "pixyslam/optimised_map";
inline constexpr std::string_view kRobotSightingTopic = "pixyslam/robot_sighting";
inline constexpr std::string_view kFleetMapTopic = "pixyslam/fleet_map";

// Message type -> its topic, generated TopicDataType and IDL file.
template <class Message>
struct MessageTraits;

#define PIXYSLAM_MESSAGE_TRAITS(Message, topic_name, idl_stem_name, register_fn) \
  template <>                                                                     \
  struct MessageTraits<msg::Message> {                                            \
    using PubSubType = msg::Message##PubSubType;                                  \
    static constexpr std::string_view topic = topic_name;                         \
    static constexpr std::string_view idl_stem = idl_stem_name;                   \
    static void register_type_object() { register_fn(); }                         \
  };

PIXYSLAM_MESSAGE_TRAITS(Odometry, kOdometryTopic, "odometry", registerodometryTypes)
PIXYSLAM_MESSAGE_TRAITS(LandmarkObservation, kLandmarkObservationTopic, "landmark_observation",
                        registerlandmark_observationTypes)
PIXYSLAM_MESSAGE_TRAITS(MapState, kMapStateTopic, "map_state", registermap_stateTypes)
PIXYSLAM_MESSAGE_TRAITS(GroundTruth, kGroundTruthTopic, "ground_truth", registerground_truthTypes)
PIXYSLAM_MESSAGE_TRAITS(Diagnostics, kDiagnosticsTopic, "diagnostics", registerdiagnosticsTypes)
PIXYSLAM_MESSAGE_TRAITS(OptimisedMap, kOptimisedMapTopic, "optimised_map", registeroptimised_mapTypes)
PIXYSLAM_MESSAGE_TRAITS(RobotSighting, kRobotSightingTopic, "robot_sighting", registerrobot_sightingTypes)
PIXYSLAM_MESSAGE_TRAITS(FleetMap, kFleetMapTopic, "fleet_map", registerfleet_mapTypes)

#undef PIXYSLAM_MESSAGE_TRAITS

// A message type as a value, for generic lambdas: [](auto tag) { using M = typename decltype(tag)::type; }.
template <class Message>
struct MessageTag {
  using type = Message;
};

// Calls f(MessageTag<M>{}) with the message type M of `topic`; false (and no
// call) when it is not one of the system's topics. The one place that maps a
// topic name to its type at run time.
template <class F>
bool visit_topic_type(std::string_view topic, F&& f) {
  if (topic == kOdometryTopic) return f(MessageTag<msg::Odometry>{}), true;
  if (topic == kLandmarkObservationTopic) return f(MessageTag<msg::LandmarkObservation>{}), true;
  if (topic == kMapStateTopic) return f(MessageTag<msg::MapState>{}), true;
  if (topic == kGroundTruthTopic) return f(MessageTag<msg::GroundTruth>{}), true;
  if (topic == kDiagnosticsTopic) return f(MessageTag<msg::Diagnostics>{}), true;
  if (topic == kOptimisedMapTopic) return f(MessageTag<msg::OptimisedMap>{}), true;
  if (topic == kRobotSightingTopic) return f(MessageTag<msg::RobotSighting>{}), true;
  if (topic == kFleetMapTopic) return f(MessageTag<msg::FleetMap>{}), true;
  return false;
}

}  // namespace pixyslam::dds
