"""The one place for ctypes: the binding to libmartello.

``native`` loads the library and binds the model, run and registry functions of the C API;
``ground_motion`` declares the ground-motion functions (c/ground_motion.c) on the same
library. No other module of the package calls ctypes."""
