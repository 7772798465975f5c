# rigcal_target_warnings(target): the project's warning policy, applied to every target of ours.
function(rigcal_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror -Wnon-virtual-dtor)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wshadow=local)
  else()  # clang: TSan and fuzz builds
    target_compile_options(${target} PRIVATE -Wshadow-uncaptured-local)
  endif()
endfunction()

# rigcal_add_library(name SOURCES...): one library per source folder, public headers in include/.
function(rigcal_add_library name)
  add_library(${name} ${ARGN})
  add_library(rigcal::${name} ALIAS ${name})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  rigcal_target_warnings(${name})
endfunction()
