from glob import glob

from setuptools import find_packages, setup

package_name = 'force_renderer'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools', 'numpy'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='Spring-damper haptic force rendering along the surface normal, kept passive.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'force_node = force_renderer.node:main',
        ],
    },
)
