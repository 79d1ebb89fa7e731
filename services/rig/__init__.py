"""The simulated rig: tool controller and sensors of one station on a CAN bus.

Physics from the paper's Sections 3-4 (:mod:`services.rig.physics`, pure);
the runtime of a real station never imports this package.
"""
