//! Navigation: what path to fly now. Filled in stage by stage (path manager, mission executor).
