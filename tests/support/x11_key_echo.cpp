// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_x11_key_echo: a tiny, unmodified-style X11 program for the x11 session tests. It fills the screen with
// one window, prints "key <keysym name>" for every key press (flushed at once) and repaints the window in a
// colour picked by the keysym, so that a test sees a key both in its output and in the picture. Before any key
// the window is dark grey (48, 48, 48); every key colour has each channel at 128 or more. A band of noise along
// the top (paint) makes each picture a real one.
//   rfbsim_x11_key_echo           run until killed or the display goes away; "mapped WxH" once it can take keys
//   rfbsim_x11_key_echo --probe   only open the display: exit 0 if that worked (prints "opened"), 1 if not
#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

// A colour of the default colormap for 8-bit channels; black when none can be had.
unsigned long pixel_for(Display* display, int red, int green, int blue) {
  XColor colour{};
  colour.red = static_cast<unsigned short>(red * 257);
  colour.green = static_cast<unsigned short>(green * 257);
  colour.blue = static_cast<unsigned short>(blue * 257);
  colour.flags = DoRed | DoGreen | DoBlue;
  if (XAllocColor(display, DefaultColormap(display, DefaultScreen(display)), &colour) == 0) {
    return BlackPixel(display, DefaultScreen(display));
  }
  return colour.pixel;
}

// A bright colour for `keysym`: a hash spreads neighbouring keysyms apart.
unsigned long key_pixel(Display* display, KeySym keysym) {
  const auto hash = static_cast<std::uint32_t>(keysym) * 2654435761U;
  return pixel_for(display, 128 + static_cast<int>(hash >> 25), 128 + static_cast<int>((hash >> 17) & 127U),
                   128 + static_cast<int>((hash >> 9) & 127U));
}

// Repaints the window: its background colour, and a band of noise along the top quarter. The noise makes the
// first picture a real one of several KiB, as any program's is: a flat screen is a few bytes of RFB, which
// sim_manager would not count as the participant having seen a picture. The centre stays the background.
void paint(Display* display, Window window, GC gc, unsigned width, unsigned height) {
  XClearWindow(display, window);
  constexpr unsigned kBlock = 4;
  std::uint32_t state = 12345;
  for (unsigned y = 0; y < height / 4; y += kBlock) {
    for (unsigned x = 0; x < width; x += kBlock) {
      state = state * 1664525U + 1013904223U;
      // 24-bit TrueColor, as Xvnc's default visual: the pixel is the colour.
      XSetForeground(display, gc, state >> 8);
      XFillRectangle(display, window, gc, static_cast<int>(x), static_cast<int>(y), kBlock, kBlock);
    }
  }
  XFlush(display);
}

}  // namespace

int main(int argc, char** argv) {
  const bool probe = argc > 1 && std::strcmp(argv[1], "--probe") == 0;
  Display* display = XOpenDisplay(nullptr);
  if (display == nullptr) {
    const char* name = std::getenv("DISPLAY");
    std::fprintf(stderr, "rfbsim_x11_key_echo: cannot open display '%s'\n", name != nullptr ? name : "");
    return 1;
  }
  if (probe) {
    std::printf("opened\n");
    XCloseDisplay(display);
    return 0;
  }

  // One window over the whole screen (Xvnc runs no window manager: it stays where it is put).
  const int screen = DefaultScreen(display);
  const auto width = static_cast<unsigned>(DisplayWidth(display, screen));
  const auto height = static_cast<unsigned>(DisplayHeight(display, screen));
  const Window window = XCreateSimpleWindow(display, RootWindow(display, screen), 0, 0, width, height, 0, 0,
                                            pixel_for(display, 48, 48, 48));
  XStoreName(display, window, "rfbsim_x11_key_echo");
  XSelectInput(display, window, KeyPressMask | ExposureMask | StructureNotifyMask);
  XMapWindow(display, window);
  const GC gc = XCreateGC(display, window, 0, nullptr);

  for (;;) {
    XEvent event{};
    XNextEvent(display, &event);
    switch (event.type) {
      case MapNotify:
        // Keys go to the focus window; with no window manager nobody else gives it to us.
        XSetInputFocus(display, window, RevertToParent, CurrentTime);
        std::printf("mapped %ux%u\n", width, height);
        std::fflush(stdout);
        break;
      case Expose:
        if (event.xexpose.count == 0) paint(display, window, gc, width, height);
        break;
      case KeyPress: {
        const KeySym keysym = XLookupKeysym(&event.xkey, 0);
        const char* name = XKeysymToString(keysym);
        std::printf("key %s\n", name != nullptr ? name : "NoSymbol");
        std::fflush(stdout);
        XSetWindowBackground(display, window, key_pixel(display, keysym));
        paint(display, window, gc, width, height);
        break;
      }
      default:
        break;
    }
  }
}
