# DDS Security (docs/security.md): a secure swarm flies and records; no one
# without credentials gets in; agent K commands only drone K; the recorder
# only reads. Included from tests/CMakeLists.txt (uses ddswarm_process_test).
add_executable(secure_probe secure_probe.cpp)
target_link_libraries(secure_probe PRIVATE ddswarm_common)

ddswarm_process_test(mp_secure_swarm 90 secure_swarm_test.sh)
ddswarm_process_test(mp_secure_per_drone 90 secure_per_drone_test.sh)
ddswarm_process_test(mp_secure_swarm_24 180 secure_swarm_scale_test.sh)
# Agents that announce themselves to the server and tools only never meet.
ddswarm_process_test(mp_agents_never_meet 60 agents_never_meet_test.sh)
# An LD_PRELOAD fault: the first participant of a process never gets a
# handshake message through (tests/stall_handshake.cpp).
add_library(stall_handshake MODULE stall_handshake.cpp)
target_link_libraries(stall_handshake PRIVATE ${CMAKE_DL_LIBS})
set_target_properties(stall_handshake PROPERTIES PREFIX "" LIBRARY_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
ddswarm_process_test(mp_secure_handshake_stall 120 secure_handshake_stall_test.sh)
