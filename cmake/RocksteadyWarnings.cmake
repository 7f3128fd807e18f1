# Warnings are errors on the project's own targets (never on third-party code).
function(rocksteady_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE
      -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
      -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
      -Wnull-dereference -Wdouble-promotion -Wformat=2 -Werror)
  endif()
endfunction()

# Flight-core flags: no exceptions, no RTTI. Used for the gnc "can fly" check and bare metal.
function(rocksteady_freestanding_flags target)
  target_compile_options(${target} PRIVATE -fno-exceptions -fno-rtti)
endfunction()
