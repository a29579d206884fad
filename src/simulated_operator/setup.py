from setuptools import find_packages, setup

package_name = 'simulated_operator'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools', 'numpy', 'pyyaml'],
    zip_safe=False,
    maintainer='Haptic toolkit maintainers',
    maintainer_email='maintainers@haptic-telesono.invalid',
    description='The simulated operator: scripted targets and the hand that holds the '
                'simulated wand.',
    license='Apache-2.0',
    entry_points={
        'haptic_wand_driver.wands': [
            'simulated = simulated_operator.assembly:simulated_wand',
        ],
    },
)
