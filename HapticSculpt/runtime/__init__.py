"""The runtime layer: threaded sculpting sessions over the C++ loops, devices and replays. It
builds on the document layer and never imports a GUI module."""
