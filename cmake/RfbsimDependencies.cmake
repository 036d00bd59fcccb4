# SPDX-License-Identifier: GPL-2.0-or-later
# Every third-party dependency, found from Debian's packages (see the README for the package list).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(LibVNCServer CONFIG REQUIRED)          # LibVNCServer::vncserver, LibVNCServer::vncclient
find_package(OpenGL REQUIRED COMPONENTS EGL OpenGL)  # OpenGL::EGL, OpenGL::OpenGL (GLVND)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)          # Eigen3::Eigen
find_package(yaml-cpp 0.7 REQUIRED CONFIG)           # yaml-cpp (scenario files, map_server YAML)
pkg_check_modules(ODE REQUIRED IMPORTED_TARGET ode)  # PkgConfig::ODE (ODE has no CMake config)
pkg_check_modules(PNG REQUIRED IMPORTED_TARGET libpng)  # PkgConfig::PNG (map images)
find_package(websocketpp CONFIG REQUIRED)            # websocketpp::websocketpp (header-only): sim_manager, tests
find_package(Boost REQUIRED COMPONENTS system)       # websocketpp's asio transport
find_package(OpenSSL 3 REQUIRED)                     # OpenSSL::SSL, OpenSSL::Crypto: TLS, signed links, tokens
find_package(SQLite3 REQUIRED)                       # SQLite::SQLite3: sim_manager's session index
find_package(CLI11 2 REQUIRED CONFIG)                # CLI11::CLI11 (header-only): every command line
find_package(nlohmann_json 3 REQUIRED CONFIG)        # nlohmann_json::nlohmann_json: session data (record/, tools/)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)  # PkgConfig::ZSTD: session.mcap's chunks (simulator/ros/mcap)
find_package(ZLIB REQUIRED)                          # ZLIB::ZLIB: crc32 for session.mcap's CRCs
find_package(Freetype REQUIRED)                      # Freetype::Freetype: the HUD's text (render/)
# libavcodec/-format/-util and libswscale: sim_replay's H.264 video (FFmpeg has no CMake config)
pkg_check_modules(LIBAV REQUIRED IMPORTED_TARGET libavcodec libavformat libavutil libswscale)
# The HUD's font: DejaVu Sans from fonts-dejavu-core, looked up at run time in this folder first.
find_file(RFBSIM_HUD_FONT DejaVuSans.ttf PATHS /usr/share/fonts/truetype/dejavu NO_DEFAULT_PATH
          DOC "TrueType font for the HUD (fonts-dejavu-core)")
if(NOT RFBSIM_HUD_FONT)
  message(FATAL_ERROR "rfbsim: DejaVuSans.ttf not found (apt-get install fonts-dejavu-core, or set RFBSIM_HUD_FONT)")
endif()
if(RFBSIM_BUILD_TESTS)
  find_package(Catch2 2 REQUIRED)
  include(Catch)
endif()
