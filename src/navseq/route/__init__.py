"""A mission's route on a map: its legs planned (:mod:`~navseq.route.legs`) and the
shortest order to visit its waypoints in (:mod:`~navseq.route.order`)."""
