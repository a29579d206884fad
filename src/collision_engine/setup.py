from glob import glob

from setuptools import find_packages, setup

package_name = 'collision_engine'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/scenes', glob('scenes/*.yaml')),
        ('share/' + package_name + '/scenes/meshes', glob('scenes/meshes/*')),
    ],
    install_requires=['setuptools', 'numpy', 'numba', 'pyyaml'],
    extras_require={'mesh': ['trimesh'], 'fcl': ['python-fcl']},
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='Exact signed distance between a haptic wand tip and a scene, with our own GJK.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'collision_node = collision_engine.node:main',
        ],
    },
)
