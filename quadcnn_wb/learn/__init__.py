"""Learning the singular structure (paper §2.2, §3): shape families, dataset, network, training.

Everything here except `families`, `augment` and `dataset` needs the optional torch extra.
"""
