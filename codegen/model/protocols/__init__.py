"""The protocols a vehicle's devices speak, one entry each (description.py: what an entry says; cyphal.py,
dronecan.py: the entries; registry.py: the one list of them). Import the module that holds a name, not this
package."""
