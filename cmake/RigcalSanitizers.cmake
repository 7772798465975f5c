# Sanitizer builds apply to every target (ours and the test framework's main), so they are set globally.
# Line tables are all a sanitizer report needs (file:line in every frame); full debug info (Debug's -g)
# made these builds about a quarter slower to compile and link.
if(RIGCAL_SANITIZE)
  set(CMAKE_CXX_FLAGS_DEBUG "")
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    set(rigcal_line_tables -g1)
    # GCC's flow analysis of sanitizer-instrumented code reports uninitialised members that are not
    # (std::regex's std::function in libstdc++ 12, at -O1 with ASan); the Release build keeps the warning.
    add_compile_options(-Wno-maybe-uninitialized)
  else()
    set(rigcal_line_tables -gline-tables-only)
  endif()
endif()

if(RIGCAL_SANITIZE STREQUAL "address")
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -O1
                      ${rigcal_line_tables})
  add_link_options(-fsanitize=address,undefined)
elseif(RIGCAL_SANITIZE STREQUAL "thread")
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer -O1 ${rigcal_line_tables})
  add_link_options(-fsanitize=thread)
elseif(RIGCAL_SANITIZE)
  message(FATAL_ERROR "RIGCAL_SANITIZE must be 'address', 'thread' or empty, not '${RIGCAL_SANITIZE}'")
endif()
