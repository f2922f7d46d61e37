# Warnings every project target links PRIVATE (never leaked to users of the libraries).
add_library(meniscus_warnings INTERFACE)
target_compile_options(meniscus_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor -Wno-unused-parameter)
# Internal invariant checks (MENISCUS_ASSERT) stay on in Release unless switched off.
add_library(meniscus_options INTERFACE)
if(MENISCUS_ASSERTS)
  target_compile_definitions(meniscus_options INTERFACE MENISCUS_ENABLE_ASSERTS=1)
endif()
