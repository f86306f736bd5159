# DDS Security (docs/security.md): a secure swarm flies and records; no one
# without credentials gets in; agent K commands only drone K; the recorder
# only reads. Included from tests/CMakeLists.txt (uses ddswarm_process_test).
add_executable(secure_probe secure_probe.cpp)
target_link_libraries(secure_probe PRIVATE ddswarm_common)

ddswarm_process_test(mp_secure_swarm 90 secure_swarm_test.sh)
ddswarm_process_test(mp_secure_per_drone 90 secure_per_drone_test.sh)
