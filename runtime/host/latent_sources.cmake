# CPU batch runtime over the latent semantics; included by runtime/host/CMakeLists.txt.
find_package(Threads REQUIRED)
target_sources(kage_runtime_host PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cpu_batch.cpp)
target_link_libraries(kage_runtime_host PUBLIC Threads::Threads)
