"""Tracking building blocks shared by methods: filters (Kalman, UKF, particle filter), the
motion model, association, online boosting, AdaBoost, colour moments, thermal silhouettes;
and the tracker protocol (:mod:`rgbd_eval.track.protocol`). Each paper's tracker lives in
its method package, ``rgbd_eval.methods.<key>``."""
