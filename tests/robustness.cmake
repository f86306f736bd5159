# Robustness: hostile samples, duplicate agents, broken configuration, and
# proof that the default DDS set-up never leaves the machine.
# Included from tests/CMakeLists.txt (uses ddswarm_process_test from there).
add_executable(hostile_publisher hostile_publisher.cpp)
target_link_libraries(hostile_publisher PRIVATE ddswarm_common)

ddswarm_process_test(mp_hostile_samples 60 hostile_samples_test.sh)
ddswarm_process_test(mp_duplicate_agent 90 duplicate_agent_test.sh)
# A second server whose host's clock is off: a swarm with a mission never yields to it.
add_executable(rival_server rival_server.cpp)
target_link_libraries(rival_server PRIVATE ddswarm_common)
ddswarm_process_test(mp_rival_server 60 rival_server_test.sh)
ddswarm_process_test(mp_config_errors 60 config_errors_test.sh)
ddswarm_process_test(mp_network_safety 60 network_safety_test.sh)
# It counts the bytes on its own veth pair: alone, as the multi-host tests.
set_tests_properties(mp_network_safety PROPERTIES SKIP_RETURN_CODE 77 RUN_SERIAL TRUE)

# Samples malformed on the wire (a bool byte of 2): refused, counted, never fatal.
add_executable(malformed_publisher malformed_publisher.cpp)
target_link_libraries(malformed_publisher PRIVATE ddswarm_common)
ddswarm_process_test(mp_malformed_samples 60 malformed_samples_test.sh)
# Bad command-line input (NaN, inf, huge, garbage), Ctrl-C, and the console at end of input.
ddswarm_process_test(mp_cli_bad_input 90 cli_bad_input_test.sh)
