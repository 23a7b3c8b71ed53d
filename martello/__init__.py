"""martello: verification and benchmark suite for contact and impact in structural dynamics.

The package by concern, from the bottom up; each layer imports only the layers below it
(tests/test_imports.py checks it):

0. ``errors``, ``paths``, ``history``: exceptions, the checkout's folders, time histories;
1. ``binding`` (the ctypes binding to libmartello, the only ctypes code) and ``oracles``
   (closed forms, written from the mathematics alone);
2. ``scene`` (scene files, their generators and variants) and ``ground_motion`` (records,
   spectra, synthetic accelerograms);
3. ``run`` (one scene), then ``batch`` (many, on the local cores);
4. ``metrics`` (scores), then ``reference`` (what a run is scored against);
5. ``checks``: runs verified against closed forms and reference data, the P4 measures;
6. ``study``, ``compare``, ``report``, then ``plot``, then ``cli``: the front ends.
"""
