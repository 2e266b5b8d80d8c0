# Full CPU environment (CpuBatch plus rendering) and the golden replay; included by runtime/host/CMakeLists.txt.
target_sources(kage_runtime_host PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cpu_env.cpp)
target_sources(kage_runtime_host PRIVATE ${CMAKE_CURRENT_LIST_DIR}/golden_check.cpp)
target_sources(kage_runtime_host PRIVATE ${CMAKE_CURRENT_LIST_DIR}/host_batch.cpp)
