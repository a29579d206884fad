from glob import glob

from setuptools import find_packages, setup

package_name = 'ultrasound_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*')),
    ],
    install_requires=['setuptools', 'numpy', 'scipy', 'numba', 'trimesh'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='A simulated B-mode ultrasound image from the probe pose in the scene anatomy, '
                'and the scanner node that publishes it.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'make_anatomy = ultrasound_sim.phantom_anatomy:main',
            'probe_imager = ultrasound_sim.node:main',
        ],
    },
)
