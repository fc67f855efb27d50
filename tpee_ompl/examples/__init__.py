"""Example problems for dimension-RRT: TPEE cross-sector queries and a plain-OMPL planar arm."""
