"""Example problems for dimension-RRT: TPEE cross-sector queries, a plain-OMPL planar arm and two continuous joints."""
