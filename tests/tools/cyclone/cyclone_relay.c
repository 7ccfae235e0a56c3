/* cyclone_relay: Eclipse Cyclone DDS (its default configuration: no
 * CYCLONEDDS_URI) reading every pixyslam topic on one domain and writing each
 * sample unchanged on the same topic of another domain, with types generated
 * by Cyclone's idlc from the project's IDL. Interop test of issue 21
 * (tests/cyclone_interop_test.sh): Fast DDS writer -> Cyclone reader, and
 * Cyclone writer -> Fast DDS reader, compared field by field by the caller.
 *   cyclone_relay IN_DOMAIN OUT_DOMAIN SECONDS
 * Prints "ready" once every writer has matched a reader on OUT_DOMAIN (so that
 * nothing relayed is lost to a reader not yet there; 30 s for all, else exit 1),
 * then "relayed TOPIC N" per topic at the end (after SECONDS or SIGINT/SIGTERM).
 * Exit status: 0 ok, 1 DDS error, no reader matched, or written samples not
 * acknowledged within 5 s; 2 usage error. A process ending frees every entity. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"
#include "diagnostics.h"
#include "ground_truth.h"
#include "landmark_observation.h"
#include "map_state.h"
#include "odometry.h"
#include "fleet_map.h"
#include "optimised_map.h"
#include "robot_sighting.h"

typedef struct {
  const char* topic;
  const dds_topic_descriptor_t* type;
  dds_entity_t reader;
  dds_entity_t writer;
  unsigned long long relayed;
} route_t;

static route_t routes[] = {
    {"pixyslam/odometry", &pixyslam_msg_Odometry_desc, 0, 0, 0},
    {"pixyslam/landmark_observation", &pixyslam_msg_LandmarkObservation_desc, 0, 0, 0},
    {"pixyslam/map_state", &pixyslam_msg_MapState_desc, 0, 0, 0},
    {"pixyslam/ground_truth", &pixyslam_msg_GroundTruth_desc, 0, 0, 0},
    {"pixyslam/diagnostics", &pixyslam_msg_Diagnostics_desc, 0, 0, 0},
    {"pixyslam/optimised_map", &pixyslam_msg_OptimisedMap_desc, 0, 0, 0},
    {"pixyslam/robot_sighting", &pixyslam_msg_RobotSighting_desc, 0, 0, 0},
    {"pixyslam/fleet_map", &pixyslam_msg_FleetMap_desc, 0, 0, 0},
};
enum { kRoutes = sizeof(routes) / sizeof(routes[0]), kBatch = 32 };

static volatile sig_atomic_t stop_requested = 0;
static void on_signal(int signal_number) {
  (void)signal_number;
  stop_requested = 1;
}

static int fail(const char* what, dds_return_t rc) {
  fprintf(stderr, "cyclone_relay: %s: %s\n", what, dds_strretcode(rc));
  return 1;
}

static int parse_int(const char* text, long min, long max, long* out) {
  char* end = NULL;
  const long v = strtol(text, &end, 10);
  if (end == text || *end != '\0' || v < min || v > max) return 0;
  *out = v;
  return 1;
}

int main(int argc, char** argv) {
  long in_domain = 0, out_domain = 0, seconds = 0;
  if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
    printf("Relays every pixyslam topic from one DDS domain to another with Cyclone DDS.\n"
           "Usage: cyclone_relay IN_DOMAIN OUT_DOMAIN SECONDS\n");
    return 0;
  }
  if (argc != 4 || !parse_int(argv[1], 0, 232, &in_domain) || !parse_int(argv[2], 0, 232, &out_domain) ||
      !parse_int(argv[3], 1, 3600, &seconds) || in_domain == out_domain) {
    fprintf(stderr, "cyclone_relay: usage: cyclone_relay IN_DOMAIN OUT_DOMAIN SECONDS (two different domains 0..232)\n");
    return 2;
  }
  signal(SIGINT, on_signal);
  signal(SIGTERM, on_signal);

  const dds_entity_t in = dds_create_participant((dds_domainid_t)in_domain, NULL, NULL);
  if (in < 0) return fail("participant (in)", in);
  const dds_entity_t out = dds_create_participant((dds_domainid_t)out_domain, NULL, NULL);
  if (out < 0) return fail("participant (out)", out);

  /* Reliable and keep-all both ways; the writer offers transient-local, the
   * strongest durability the project's readers ask for (MapState). */
  dds_qos_t* reader_qos = dds_create_qos();
  dds_qset_reliability(reader_qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_history(reader_qos, DDS_HISTORY_KEEP_ALL, 0);
  dds_qos_t* writer_qos = dds_create_qos();
  dds_qset_reliability(writer_qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_history(writer_qos, DDS_HISTORY_KEEP_ALL, 0);
  dds_qset_durability(writer_qos, DDS_DURABILITY_TRANSIENT_LOCAL);

  const dds_entity_t waitset = dds_create_waitset(in);
  if (waitset < 0) return fail("waitset", waitset);
  for (int i = 0; i < kRoutes; ++i) {
    route_t* r = &routes[i];
    const dds_entity_t in_topic = dds_create_topic(in, r->type, r->topic, NULL, NULL);
    const dds_entity_t out_topic = dds_create_topic(out, r->type, r->topic, NULL, NULL);
    if (in_topic < 0 || out_topic < 0) return fail(r->topic, in_topic < 0 ? in_topic : out_topic);
    r->reader = dds_create_reader(in, in_topic, reader_qos, NULL);
    r->writer = dds_create_writer(out, out_topic, writer_qos, NULL);
    if (r->reader < 0 || r->writer < 0) return fail(r->topic, r->reader < 0 ? r->reader : r->writer);
    const dds_entity_t condition = dds_create_readcondition(r->reader, DDS_ANY_STATE);
    if (condition < 0) return fail("read condition", condition);
    const dds_return_t attached = dds_waitset_attach(waitset, condition, (dds_attach_t)i);
    if (attached < 0) return fail("waitset", attached);
  }
  dds_delete_qos(reader_qos);
  dds_delete_qos(writer_qos);
  const dds_time_t give_up = dds_time() + DDS_SECS(30);
  for (int i = 0; i < kRoutes; ++i) {
    dds_publication_matched_status_t matched = {0};
    while (dds_get_publication_matched_status(routes[i].writer, &matched) == DDS_RETCODE_OK &&
           matched.current_count == 0) {
      if (stop_requested) return 0;
      if (dds_time() > give_up) {
        fprintf(stderr, "cyclone_relay: no reader of %s on domain %ld after 30 s\n", routes[i].topic, out_domain);
        return 1;
      }
      dds_sleepfor(DDS_MSECS(20));
    }
  }
  printf("ready\n");
  fflush(stdout);

  const dds_time_t end = dds_time() + DDS_SECS(seconds);
  while (!stop_requested && dds_time() < end) {
    dds_attach_t triggered[kRoutes];
    const dds_return_t n = dds_waitset_wait(waitset, triggered, kRoutes, DDS_MSECS(200));
    if (n < 0) return fail("wait", n);
    for (dds_return_t k = 0; k < n; ++k) {
      route_t* r = &routes[(int)triggered[k]];
      for (;;) {
        void* samples[kBatch] = {NULL};
        dds_sample_info_t infos[kBatch];
        const dds_return_t taken = dds_take(r->reader, samples, infos, kBatch, kBatch);
        if (taken < 0) return fail("take", taken);
        for (dds_return_t s = 0; s < taken; ++s) {
          if (!infos[s].valid_data) continue;
          const dds_return_t written = dds_write(r->writer, samples[s]);
          if (written < 0) return fail("write", written);
          ++r->relayed;
        }
        if (taken > 0) dds_return_loan(r->reader, samples, taken);
        if (taken < kBatch) break;
      }
    }
  }
  /* The readers on the other domain acknowledge what was written. */
  int status = 0;
  for (int i = 0; i < kRoutes; ++i) {
    const dds_return_t acked = dds_wait_for_acks(routes[i].writer, DDS_SECS(5));
    if (acked < 0) {
      fprintf(stderr, "cyclone_relay: %s: not acknowledged: %s\n", routes[i].topic, dds_strretcode(acked));
      status = 1;
    }
  }
  for (int i = 0; i < kRoutes; ++i) printf("relayed %s %llu\n", routes[i].topic, routes[i].relayed);
  dds_delete(DDS_CYCLONEDDS_HANDLE);
  return status;
}
