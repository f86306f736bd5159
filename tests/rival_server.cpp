// Two swarms on one domain: plays a second server whose clock is
// off. It publishes a Scene of its own instance, stamped --clock-offset
// seconds from now (as a host whose clock is that far off would), and then
// SimStatus samples of that instance twice a second, with a mission in force
// for drone 0 when --mission is given, for --duration seconds.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>

#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

int main(int argc, char** argv) {
  return run_main("rival_server", [&]() -> int {
    CLI::App app{"play a second server on the domain"};
    DdsConfig dds;
    double offset_s = 0, duration_s = 5;
    bool mission = false;
    app.add_option("--domain", dds.domain_id);
    app.add_option("--clock-offset", offset_s, "s added to the scene's source timestamp");
    app.add_option("--duration", duration_s, "s of status samples");
    app.add_flag("--mission", mission, "report a mission in force for drone 0");
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();
    Participant p(dds, "rival_server");
    const std::uint64_t me = random_instance();
    auto scenes = p.writer<msg::Scene>();
    auto statuses = p.writer<msg::SimStatus>();
    msg::Scene scene;
    scene.name("rival");
    scene.server_instance(me);
    scene.num_drones(6);
    scene.control_rate_hz(50);
    scene.physics_rate_hz(1000);
    const auto stamp = std::chrono::system_clock::now().time_since_epoch() +
                       std::chrono::duration_cast<std::chrono::nanoseconds>(
                           std::chrono::duration<double>(offset_s));
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(stamp).count();
    eprosima::fastrtps::Time_t t;
    t.seconds = static_cast<std::int32_t>(ns / 1000000000);
    t.nanosec = static_cast<std::uint32_t>(ns % 1000000000);
    if (scenes.raw()->write_w_timestamp(&scene, fdds::HANDLE_NIL, t) != ReturnCode_t::RETCODE_OK)
      throw std::runtime_error("the scene was not written");
    std::printf("rival server %016llx: scene stamped %+.0f s\n",
                static_cast<unsigned long long>(me), offset_s);
    std::fflush(stdout);
    msg::SimStatus s;
    s.server_instance(me);
    s.num_drones(6);
    s.mission_seq(std::vector<std::uint32_t>(6, 0));
    if (mission) s.mission_seq()[0] = 7;
    const double end = wall_seconds() + duration_s;
    for (std::uint64_t tick = 1; wall_seconds() < end && !stop_requested(); ++tick) {
      s.tick(tick);
      statuses.write(s);
      wait_for_stop(std::chrono::milliseconds(500));
    }
    return 0;
  });
}
