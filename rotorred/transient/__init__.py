"""transient"""
